// The benchmarks as calls (Lucent::bench): bench_build_json, bench_spheres_json,
// bench_curves_json, bench_igi_json, bench_fog_json and bench_tea_json return the document
// their `lucent bench <name> --json` prints, print nothing, and refuse a bad option by its
// name (as the call's field and as the CLI's flag) before measuring anything.
#include <gtest/gtest.h>

#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "bench/build/build_bench.h"
#include "bench/curves/curves_bench.h"
#include "bench/fog/fog_bench.h"
#include "bench/igi/igi_bench.h"
#include "bench/spheres/spheres_bench.h"
#include "bench/tea/tea_bench.h"
#include "lucent/error.h"

namespace {

using nlohmann::json;

const std::string kRoom = std::string(LUCENT_TESTS_DIR) + "/../examples/bench-rays/room.obj";

/// The document `call` returns, with stdout captured to check that nothing was printed.
json quiet_document(const std::function<std::string()>& call) {
    testing::internal::CaptureStdout();
    const std::string text = call();
    EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
    return json::parse(text);
}

/// Whether `call` throws a lucent::Error whose message holds `words`; the message (or that
/// none came) when not.
testing::AssertionResult refused_with(const std::function<void()>& call, const std::string& words) {
    std::string message = "(no error)";
    try {
        call();
    } catch (const lucent::Error& e) {
        message = e.what();
    }
    if (message.find(words) != std::string::npos) return testing::AssertionSuccess();
    return testing::AssertionFailure() << "expected \"" << words << "\" in: " << message;
}

lucent::bench::BuildBenchOptions small_build() {
    lucent::bench::BuildBenchOptions o;
    o.scene = kRoom;
    o.repeat = 1;
    o.peer = false;
    return o;
}

TEST(BenchCalls, BuildReturnsTheTreeItTimed) {
    lucent::bench::BuildBenchOptions o = small_build();
    o.threads = 1;  // Lucent's build on one thread, as Embree's would be
    const json d = quiet_document([&] { return lucent::bench::bench_build_json(o); });
    EXPECT_EQ(d.at("triangles"), 2242);
    EXPECT_EQ(d.at("threads"), 1);
    EXPECT_GT(d.at("build_ms").get<double>(), 0.0);
    EXPECT_GT(d.at("wide_nodes").get<int>(), 0);
    EXPECT_FALSE(d.contains("embree_build_ms"));  // peer = false
    o.subdivide = 1;
    EXPECT_EQ(json::parse(lucent::bench::bench_build_json(o)).at("triangles"), 4 * 2242);
}

TEST(BenchCalls, BuildRefusesBadOptionsByName) {
    // The build's options, changed by `change`, are refused with `words` in the message.
    auto refuses = [](auto change, const std::string& words) {
        lucent::bench::BuildBenchOptions o = small_build();
        change(o);
        return refused_with([&] { lucent::bench::bench_build_json(o); }, words);
    };
    EXPECT_TRUE(
        refuses([](auto& o) { o.repeat = 0; }, "repeat (--repeat) is 0; it must lie in [1, 1000]"));
    EXPECT_TRUE(refuses([](auto& o) { o.subdivide = 6; }, "subdivide (--subdivide) is 6"));
    EXPECT_TRUE(refuses([](auto& o) { o.backend = "gpu"; }, "backend (--backend) is \"gpu\""));
    EXPECT_TRUE(refuses([](auto& o) { o.scene.clear(); }, "no scene (scene, --scene)"));
    EXPECT_TRUE(refuses([](auto& o) { o.scene += ".missing.obj"; }, "room.obj.missing.obj"));
}

TEST(BenchCalls, SpheresAndCurvesReturnTheirHitsAndRefuseBadCounts) {
    lucent::bench::SpheresBenchOptions spheres;
    spheres.count = 3000, spheres.width = 64, spheres.height = 48, spheres.repeat = 1;
    const json s = quiet_document([&] { return lucent::bench::bench_spheres_json(spheres); });
    EXPECT_EQ(s.at("benchmark"), "spheres");
    EXPECT_EQ(s.at("pixels_that_differ"), 0);
    EXPECT_GT(s.at("hit_fraction").get<double>(), 0.0);
    spheres.count = 0;
    EXPECT_TRUE(refused_with([&] { lucent::bench::bench_spheres_json(spheres); },
                             "bench spheres: count (--count) is 0"));

    lucent::bench::CurvesBenchOptions curves;
    curves.segments = 2000, curves.width = 64, curves.height = 48, curves.repeat = 1;
    const json c = quiet_document([&] { return lucent::bench::bench_curves_json(curves); });
    EXPECT_EQ(c.at("benchmark"), "curves");
    EXPECT_GT(c.at("primary_hit_fraction").get<double>(), 0.0);
    curves.width = 0;
    EXPECT_TRUE(refused_with([&] { lucent::bench::bench_curves_json(curves); },
                             "the image size (size, --size) is 0x48"));
}

TEST(BenchCalls, TeaChecksumsDependOnTheSeedOfTheGeneratedKeyOnly) {
    lucent::bench::TeaBenchOptions o;
    o.megabytes = 2;
    const json a = quiet_document([&] { return lucent::bench::bench_tea_json(o); });
    o.seed = 1;
    const json b = json::parse(lucent::bench::bench_tea_json(o));
    EXPECT_EQ(a.at("fixed_checksum"), b.at("fixed_checksum"));
    EXPECT_NE(a.at("generated_checksum"), b.at("generated_checksum"));
    o.rounds = 0;
    EXPECT_TRUE(refused_with([&] { lucent::bench::bench_tea_json(o); }, "rounds (--rounds) is 0"));
}

TEST(BenchCalls, IgiAndFogReturnARowPerConfiguration) {
    lucent::bench::IgiBenchOptions igi;
    igi.width = 48, igi.height = 32, igi.frames = 1, igi.vpls = {4, 8};
    const json i = quiet_document([&] { return lucent::bench::bench_igi_json(igi); });
    ASSERT_EQ(i.at("rows").size() % 2, 0u);
    EXPECT_EQ(i.at("rows")[0].at("configuration"), "canonical");
    EXPECT_EQ(i.at("rows")[0].at("vpls"), 4);
    EXPECT_EQ(i.at("rows")[1].at("vpls"), 8);
    igi.vpls = {30, 0};
    EXPECT_TRUE(refused_with([&] { lucent::bench::bench_igi_json(igi); },
                             "a VPL count (vpls, --vpls) is 0"));
    igi.vpls = {4};
    igi.downsample = 1;
    EXPECT_TRUE(refused_with([&] { lucent::bench::bench_igi_json(igi); },
                             "downsample (--downsample) is 1; it must lie in [2, 16]"));

    lucent::bench::FogBenchOptions fog;
    fog.width = 48, fog.height = 32, fog.frames = 2;
    const json f = quiet_document([&] { return lucent::bench::bench_fog_json(fog); });
    ASSERT_EQ(f.at("rows").size(), 4u);
    EXPECT_EQ(f.at("rows")[0].at("configuration"), "no fog");
    fog.frames = 0;
    EXPECT_TRUE(
        refused_with([&] { lucent::bench::bench_fog_json(fog); }, "frames (--frames) is 0"));
}

}  // namespace

// The benchmarks' reporter (bench/common/report.h): whatever text a result holds, its JSON
// parses back to the same values; a JsonCapture takes the document instead of stdout, which
// is how bench_rays_json returns `bench rays --json`'s document.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "bench/common/rate.h"
#include "bench/common/report.h"
#include "bench/rays/rays_bench.h"
#include "lucent/error.h"

namespace {

using lucent::bench::Json;

TEST(BenchReport, QuotesBackslashesAndNewlinesInTextParseBack) {
    const std::string scene = "scenes/my \"best\" scene\\v2\n.obj";
    const Json document{{"scene", scene}, {"triangles", 32}};
    const nlohmann::json back = nlohmann::json::parse(lucent::bench::json_text(document));
    EXPECT_EQ(back.at("scene").get<std::string>(), scene);
    EXPECT_EQ(back.at("triangles").get<int>(), 32);
}

TEST(BenchReport, BytesThatAreNotUtf8StillGiveValidJson) {
    const Json document{{"scene", std::string("caf\xe9.obj")}};  // Latin-1, not UTF-8
    const nlohmann::json back = nlohmann::json::parse(lucent::bench::json_text(document));
    EXPECT_EQ(back.at("scene").get<std::string>(), "caf\xef\xbf\xbd.obj");  // U+FFFD
}

TEST(BenchReport, KeysKeepTheOrderTheyWereWrittenIn) {
    const std::string text = lucent::bench::json_text(Json{{"scene", "a"}, {"backend", "b"}});
    EXPECT_LT(text.find("\"scene\""), text.find("\"backend\"")) << text;
}

TEST(BenchReport, RatesAreRoundedToFourPlaces) {
    const Json rate = lucent::bench::rate_json({12.345678, 11.00004, 13.99996});
    EXPECT_DOUBLE_EQ(rate.at("mrays").get<double>(), 12.3457);
    EXPECT_DOUBLE_EQ(rate.at("min").get<double>(), 11.0);
    EXPECT_DOUBLE_EQ(rate.at("max").get<double>(), 14.0);
}

TEST(BenchReport, MedianOfAnEvenCountIsTheMeanOfTheMiddleTwo) {
    EXPECT_DOUBLE_EQ(lucent::bench::median_of({4, 1, 3, 2}), 2.5);
    EXPECT_DOUBLE_EQ(lucent::bench::median_of({5, 1, 3}), 3.0);
    EXPECT_DOUBLE_EQ(lucent::bench::median_of({}), 0.0);
}

TEST(BenchReport, ACaptureTakesTheDocumentInsteadOfStdoutAndCapturesNest) {
    using lucent::bench::JsonCapture;
    testing::internal::CaptureStdout();
    {
        JsonCapture outer;
        lucent::bench::print_json(Json{{"to", "outer"}});
        {
            JsonCapture inner;
            lucent::bench::print_json(Json{{"to", "inner"}});
            EXPECT_EQ(nlohmann::json::parse(inner.text()).at("to"), "inner");
        }
        EXPECT_EQ(nlohmann::json::parse(outer.text()).at("to"), "outer");
        lucent::bench::print_json(Json{{"to", "outer again"}});
        EXPECT_EQ(nlohmann::json::parse(outer.text()).at("to"), "outer again");
    }
    lucent::bench::print_json(Json{{"to", "stdout"}});
    const std::string printed = testing::internal::GetCapturedStdout();
    EXPECT_EQ(nlohmann::json::parse(printed).at("to"), "stdout") << printed;
}

/// examples/bench-rays' scene, with its camera in the cameras.txt beside it.
lucent::bench::RaysOptions small_room() {
    lucent::bench::RaysOptions options;
    options.scene = std::string(LUCENT_TESTS_DIR) + "/../examples/bench-rays/room.obj";
    options.width = 64, options.height = 48;
    options.repeat = 1;
    options.threads = 2;
    return options;
}

TEST(BenchRaysJson, ReturnsWhatJsonPrintsAndPrintsNothing) {
    lucent::bench::RaysOptions options = small_room();
    testing::internal::CaptureStdout();
    const nlohmann::json returned = nlohmann::json::parse(lucent::bench::bench_rays_json(options));
    EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
    options.json = true;
    testing::internal::CaptureStdout();
    EXPECT_EQ(lucent::bench::run_bench_rays(options), 0);
    const nlohmann::json printed = nlohmann::json::parse(testing::internal::GetCapturedStdout());
    ASSERT_EQ(returned.size(), printed.size());
    for (auto a = returned.begin(), b = printed.begin(); a != returned.end(); ++a, ++b)
        EXPECT_EQ(a.key(), b.key());  // the same keys in the same order
    for (const char* kind : {"primary", "diffuse"}) {
        EXPECT_GT(returned["lucent"][kind]["hits"].get<int>(), 0) << kind;
        EXPECT_EQ(returned["lucent"][kind]["hits"], printed["lucent"][kind]["hits"]) << kind;
        EXPECT_EQ(returned["lucent"][kind]["sum_t"], printed["lucent"][kind]["sum_t"]) << kind;
    }
    EXPECT_EQ(returned["lucent"]["shadow"]["occluded"], printed["lucent"]["shadow"]["occluded"]);
    EXPECT_EQ(returned["streams"]["checksums_agree_with_kernels"], true);
}

TEST(BenchRaysJson, BadOptionsAreRefusedByName) {
    auto refusal = [](lucent::bench::RaysOptions options) {
        try {
            lucent::bench::bench_rays_json(options);
        } catch (const lucent::Error& e) {
            return std::string(e.what());
        }
        return std::string("(no error)");
    };
    lucent::bench::RaysOptions o = small_room();
    o.width = 0;
    EXPECT_NE(refusal(o).find("size (size, --size)"), std::string::npos) << refusal(o);
    o = small_room();
    o.repeat = 0;
    EXPECT_NE(refusal(o).find("repeat (--repeat)"), std::string::npos) << refusal(o);
    o = small_room();
    o.backend = "gpu";
    EXPECT_NE(refusal(o).find("backend (--backend) is \"gpu\""), std::string::npos) << refusal(o);
    o = small_room();
    o.scene.clear();
    EXPECT_NE(refusal(o).find("no scene"), std::string::npos) << refusal(o);
    o = small_room();
    o.has_camera = true;
    o.eye = o.look = make_float3(0, 1, 0);
    o.fov = 50;
    EXPECT_NE(refusal(o).find("eye and look are the same point"), std::string::npos) << refusal(o);
    o.eye = make_float3(0, 1, 5);
    o.fov = 0;
    EXPECT_NE(refusal(o).find("fov (--fov) is 0"), std::string::npos) << refusal(o);
    o = small_room();
    o.scene += ".missing.obj";
    EXPECT_NE(refusal(o).find("room.obj.missing.obj"), std::string::npos) << refusal(o);
}

}  // namespace

// Interactive sessions (`lucent view`'s rendering): from the sample's own camera a session
// renders what `lucent render` does; progressive sessions accumulate and restart.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "samples/sample.h"
#include "samples/settings_error.h"
#include "scene/image_io.h"
#include "test_support.h"

namespace {

using namespace lucent;
using namespace lucent::samples;

RenderSettings small_settings(unsigned width = 64, unsigned height = 48) {
    RenderSettings s;
    s.width = width;
    s.height = height;
    s.backend = lucent_tests::test_backend();
    s.threads = 2;
    return s;
}

/// The pixels whose 8-bit sRGB values differ by more than 2 in some channel.
size_t differing(const scene::Image& a, const scene::Image& b) {
    scene::Image8 x{a.width, a.height, scene::to_srgb8(a)};
    scene::Image8 y{b.width, b.height, scene::to_srgb8(b)};
    return scene::count_differing_pixels(x, y, 2);
}

float max_difference(const scene::Image& a, const scene::Image& b) {
    float d = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i) {
        const float3 e = a.pixels[i] - b.pixels[i];
        d = std::max({d, std::fabs(e.x), std::fabs(e.y), std::fabs(e.z)});
    }
    return d;
}

TEST(Session, EverySessionStartsWithItsSamplesRenderAndItsCameraMoves) {
    for (const Sample* sample : all_samples()) {
        RenderSettings s = small_settings(32, 24);
        s.spp = 1;
        auto session = sample->open(s);
        const scene::Image first = session->frame().image;
        // The same camera program and the sample's own camera in its buffer: the same pixels.
        EXPECT_EQ(max_difference(first, sample->render(s).image), 0.0f) << sample->name;
        scene::Camera moved = session->initial_camera();
        moved.eye = moved.eye + 0.3f * (moved.look - moved.eye);
        session->set_camera(moved);
        EXPECT_GT(differing(session->frame().image, first), 20u) << sample->name;
    }
}

TEST(Session, SamplesRegisterThemselvesInHelpOrder) {
    std::vector<std::string> names;
    for (const Sample* sample : all_samples()) names.push_back(sample->name);
    EXPECT_EQ(names, (std::vector<std::string>{"whitted", "direct", "igi", "radiosity",
                                               "pathtracer", "hair", "fog"}));
}

TEST(Session, WhittedFromItsOwnCameraMatchesTheRender) {
    const Sample& info = find_sample("whitted");
    const RenderSettings s = small_settings();
    auto session = info.open(s);
    EXPECT_FALSE(session->progressive());
    const FrameResult frame = session->frame();
    const RenderResult render = info.render(s);
    ASSERT_EQ(frame.image.width, 64u);
    ASSERT_EQ(frame.image.height, 48u);
    // One camera program and the sample's own camera in its buffer: the same pixels.
    EXPECT_EQ(max_difference(frame.image, render.image), 0.0f);
}

TEST(Session, WhittedCameraMovesChangeTheImageAndComeBack) {
    auto session = find_sample("whitted").open(small_settings());
    const scene::Image before = session->frame().image;
    scene::Camera moved = session->initial_camera();
    moved.eye = moved.eye + make_float3(0.0f, 3.0f, 0.0f);
    session->set_camera(moved);
    EXPECT_GT(differing(session->frame().image, before), 100u);
    // The viewer's camera (a unit W) rounds otherwise than the sample's own: a few edge pixels.
    session->set_camera(session->initial_camera());
    EXPECT_LE(differing(session->frame().image, before), 3u);
}

TEST(Session, WhittedOptionsChangeInPlaceOrAskForARebuild) {
    const Sample& info = find_sample("whitted");
    RenderSettings s = small_settings();
    auto session = info.open(s);
    EXPECT_TRUE(session->set_option("shadows", "0"));
    s.sets["shadows"] = "0";
    EXPECT_EQ(max_difference(session->frame().image, info.render(s).image), 0.0f);
    EXPECT_FALSE(session->set_option("lights", "2"));  // another light buffer: rebuild
    EXPECT_THROW(session->set_option("max_depth", "99"), SettingsError);
    EXPECT_THROW(session->set_option("nope", "1"), SettingsError);
}

TEST(Session, PathtracerAccumulatesLikeTheRenderAndRestartsWhenTheCameraMoves) {
    const Sample& info = find_sample("pathtracer");
    RenderSettings s = small_settings(32, 32);
    s.spp = 4;
    auto session = info.open(s);
    EXPECT_TRUE(session->progressive());
    FrameResult frame;
    for (unsigned i = 1; i <= 4; ++i) {
        frame = session->frame();
        EXPECT_EQ(frame.samples, i);
    }
    // Same camera program, random streams and sample count: the render's image.
    EXPECT_EQ(max_difference(frame.image, info.render(s).image), 0.0f);

    session->set_camera(session->initial_camera());
    EXPECT_EQ(session->frame().samples, 1u);
    session->frame();
    session->reset();
    const FrameResult restarted = session->frame();
    EXPECT_EQ(restarted.samples, 1u);
    RenderSettings one = s;
    one.spp = 1;
    EXPECT_LT(max_difference(restarted.image, info.render(one).image), 1e-3f);
}

TEST(Session, PathtracerExposureIsLive) {
    const Sample& info = find_sample("pathtracer");
    RenderSettings s = small_settings(32, 32);
    s.spp = 1;
    auto session = info.open(s);
    const scene::Image base = session->frame().image;
    EXPECT_TRUE(session->set_option("exposure", "2"));
    const FrameResult doubled = session->frame();
    EXPECT_EQ(doubled.samples, 1u);  // an option restarts the accumulation
    for (size_t i = 0; i < base.pixels.size(); i += 37)
        EXPECT_NEAR(doubled.image.pixels[i].x, 2.0f * base.pixels[i].x,
                    1e-4f + 1e-4f * base.pixels[i].x);
}

TEST(Session, FogFromItsOwnCameraMatchesTheRender) {
    const Sample& info = find_sample("fog");
    RenderSettings s = small_settings(48, 32);
    s.sets["step"] = "0.2";
    auto session = info.open(s);
    EXPECT_EQ(max_difference(session->frame().image, info.render(s).image), 0.0f);
    EXPECT_FALSE(session->set_option("step", "0.3"));  // fog options rebuild the scene
}

TEST(Session, DirectFromItsOwnCameraMatchesTheRenderAndRebuildsForAnOption) {
    const Sample& info = find_sample("direct");
    RenderSettings s = small_settings(32, 32);
    auto session = info.open(s);
    EXPECT_EQ(max_difference(session->frame().image, info.render(s).image), 0.0f);
    EXPECT_FALSE(session->set_option("ambient", "0.5"));  // a material variable: rebuild
    EXPECT_THROW(session->set_option("ambient", "2"), SettingsError);
}

TEST(Session, MultiPassSamplesRebuildForAnOptionAndCheckIt) {
    // {sample, an option baked into its scene, a value out of that option's range}
    const char* const cases[][3] = {
        {"igi", "max_depth", "0"}, {"radiosity", "grid", "0"}, {"fog", "max_depth", "17"}};
    for (const auto& [name, option, bad] : cases) {
        auto session = find_sample(name).open(small_settings(16, 16));
        EXPECT_FALSE(session->set_option(option, "2")) << name;  // the viewer opens a new one
        EXPECT_THROW(session->set_option(option, bad), SettingsError) << name;
        EXPECT_THROW(session->set_option("nope", "1"), SettingsError) << name;
    }
}

TEST(SampleOptions, HelpAndRangeComeFromTheDeclaration) {
    const SampleOption depth = SampleOption::integer("max_depth", 6, 1, 31, "deepest tree");
    EXPECT_EQ(depth.kind, OptionKind::kInteger);
    EXPECT_EQ(depth.default_value, "6");
    EXPECT_EQ(depth.help_with_range(), "deepest tree (1..31)");
    const SampleOption step = SampleOption::number("step", 0.05f, 1e-3f, 10.0f, "march step");
    EXPECT_EQ(step.default_value, "0.05");
    EXPECT_EQ(step.range(), "0.001..10");
    EXPECT_EQ(SampleOption::toggle("nee", true, "light sampling").default_value, "1");
    EXPECT_EQ(SampleOption::toggle("nee", true, "light sampling").range(), "0 or 1");
    EXPECT_EQ(SampleOption::text("file", "", "a map").help_with_range(), "a map");
}

TEST(SampleOptions, ValuesAreCheckedAgainstTheirKindAndRange) {
    const std::vector<SampleOption> options = {
        SampleOption::integer("max_depth", 6, 1, 31, "deepest tree"),
        SampleOption::number("exposure", 1.0f, 0.0f, 1e6f, "multiplies the image"),
        SampleOption::toggle("nee", true, "light sampling"),
        SampleOption::text("file", "", "a map")};
    const OptionValues values("s", options, {{"max_depth", "+9"}, {"file", "a.hdr"}});
    EXPECT_EQ(values.integer("max_depth"), 9);
    EXPECT_EQ(values.number("exposure"), 1.0f);
    EXPECT_TRUE(values.on("nee"));
    EXPECT_EQ(values.text("file"), "a.hdr");
    const auto message = [&](const std::map<std::string, std::string>& sets) {
        try {
            OptionValues("s", options, sets);
        } catch (const SettingsError& e) {
            return std::string(e.what());
        }
        return std::string("(no error)");
    };
    const std::string range = message({{"max_depth", "32"}});
    EXPECT_NE(range.find("--set max_depth=32: out of range"), std::string::npos) << range;
    EXPECT_NE(range.find("an integer in [1, 31]"), std::string::npos) << range;
    EXPECT_NE(range.find("deepest tree (1..31)"), std::string::npos) << range;
    const std::string number = message({{"exposure", "bright"}});
    EXPECT_NE(number.find("not a number; expected a number in [0, 1e+06]"), std::string::npos)
        << number;
    const std::string toggle = message({{"nee", "2"}});
    EXPECT_NE(toggle.find("an integer in [0, 1]"), std::string::npos) << toggle;
    const std::string unknown = message({{"nope", "1"}});
    EXPECT_NE(unknown.find("has no option 'nope'; its options are max_depth, exposure, nee, file"),
              std::string::npos)
        << unknown;
    EXPECT_THROW(values.number("max_depth"), Error);  // read as another kind: the sample's bug
}

TEST(SampleOptions, EveryDefaultHoldsItsOwnRange) {
    // The viewer's sliders start at the default: a range that excludes it is a wrong option.
    for (const Sample* sample : all_samples()) {
        EXPECT_NO_THROW(sample->read_options(RenderSettings{})) << sample->name;
        for (const SampleOption& option : sample->options) {
            if (option.kind == OptionKind::kInteger || option.kind == OptionKind::kNumber) {
                EXPECT_LT(option.lo, option.hi) << sample->name << " " << option.name;
            }
        }
    }
}

}  // namespace

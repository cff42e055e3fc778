// Interactive sessions (`lucent view`'s rendering): from the sample's own camera a session
// renders what `lucent render` does; progressive sessions accumulate and restart.
#include <gtest/gtest.h>

#include <cmath>

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

TEST(Session, SamplesWithASessionAreWhittedPathtracerAndFog) {
    EXPECT_NE(find_sample("whitted").open, nullptr);
    EXPECT_NE(find_sample("pathtracer").open, nullptr);
    EXPECT_NE(find_sample("fog").open, nullptr);
    EXPECT_EQ(find_sample("igi").open, nullptr);
}

TEST(Session, WhittedFromItsOwnCameraMatchesTheRender) {
    const SampleInfo& info = find_sample("whitted");
    const RenderSettings s = small_settings();
    auto session = open_session(info, s);
    EXPECT_FALSE(session->progressive());
    EXPECT_FALSE(session->fixed_camera());
    const FrameResult frame = session->frame();
    const RenderResult render = info.render(s);
    ASSERT_EQ(frame.image.width, 64u);
    ASSERT_EQ(frame.image.height, 48u);
    // The two compute the same pinhole frame in different float order: a few edge pixels.
    EXPECT_LE(differing(frame.image, render.image), 3u);
}

TEST(Session, WhittedCameraMovesChangeTheImageAndComeBack) {
    auto session = open_session(find_sample("whitted"), small_settings());
    const scene::Image before = session->frame().image;
    scene::Camera moved = session->initial_camera();
    moved.eye = moved.eye + make_float3(0.0f, 3.0f, 0.0f);
    session->set_camera(moved);
    EXPECT_GT(differing(session->frame().image, before), 100u);
    session->set_camera(session->initial_camera());
    EXPECT_EQ(differing(session->frame().image, before), 0u);
}

TEST(Session, WhittedOptionsChangeInPlaceOrAskForARebuild) {
    const SampleInfo& info = find_sample("whitted");
    RenderSettings s = small_settings();
    auto session = open_session(info, s);
    EXPECT_TRUE(session->set_option("shadows", "0"));
    s.sets["shadows"] = "0";
    EXPECT_LE(differing(session->frame().image, info.render(s).image), 3u);
    EXPECT_FALSE(session->set_option("lights", "2"));  // another light buffer: rebuild
    EXPECT_THROW(session->set_option("max_depth", "99"), SettingsError);
    EXPECT_THROW(session->set_option("nope", "1"), SettingsError);
}

TEST(Session, PathtracerAccumulatesLikeTheRenderAndRestartsWhenTheCameraMoves) {
    const SampleInfo& info = find_sample("pathtracer");
    RenderSettings s = small_settings(32, 32);
    s.spp = 4;
    auto session = open_session(info, s);
    EXPECT_TRUE(session->progressive());
    FrameResult frame;
    for (unsigned i = 1; i <= 4; ++i) {
        frame = session->frame();
        EXPECT_EQ(frame.samples, i);
    }
    // Same random streams, same sample count: the render's image up to the camera frame's
    // float rounding.
    EXPECT_LT(max_difference(frame.image, info.render(s).image), 1e-3f);

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
    const SampleInfo& info = find_sample("pathtracer");
    RenderSettings s = small_settings(32, 32);
    s.spp = 1;
    auto session = open_session(info, s);
    const scene::Image base = session->frame().image;
    EXPECT_TRUE(session->set_option("exposure", "2"));
    const FrameResult doubled = session->frame();
    EXPECT_EQ(doubled.samples, 1u);  // an option restarts the accumulation
    for (size_t i = 0; i < base.pixels.size(); i += 37)
        EXPECT_NEAR(doubled.image.pixels[i].x, 2.0f * base.pixels[i].x,
                    1e-4f + 1e-4f * base.pixels[i].x);
}

TEST(Session, FogFromItsOwnCameraMatchesTheRender) {
    const SampleInfo& info = find_sample("fog");
    RenderSettings s = small_settings(48, 32);
    s.sets["step"] = "0.2";
    auto session = open_session(info, s);
    EXPECT_EQ(max_difference(session->frame().image, info.render(s).image), 0.0f);
    EXPECT_FALSE(session->set_option("step", "0.3"));  // fog options rebuild the scene
}

TEST(Session, SamplesWithoutOneRenderFromTheirOwnCamera) {
    const SampleInfo& info = find_sample("direct");
    RenderSettings s = small_settings(32, 32);
    auto session = open_session(info, s);
    EXPECT_TRUE(session->fixed_camera());
    EXPECT_EQ(max_difference(session->frame().image, info.render(s).image), 0.0f);
    EXPECT_TRUE(session->set_option("ambient", "0.5"));
    s.sets["ambient"] = "0.5";
    EXPECT_EQ(max_difference(session->frame().image, info.render(s).image), 0.0f);
    EXPECT_THROW(session->set_option("nope", "1"), SettingsError);
}

TEST(OptionRange, ReadsTheRangeTheHelpStates) {
    double lo = 0, hi = 0;
    ASSERT_TRUE(option_range({"a", "1", "deepest tree (1..31)"}, lo, hi));
    EXPECT_EQ(lo, 1);
    EXPECT_EQ(hi, 31);
    ASSERT_TRUE(option_range({"a", "1", "multiplies the image (0..1e6)"}, lo, hi));
    EXPECT_EQ(hi, 1e6);
    ASSERT_TRUE(option_range({"a", "0", "selects streams (0..2^30)"}, lo, hi));
    EXPECT_EQ(hi, double(1 << 30));
    ASSERT_TRUE(option_range({"a", "0.05", "march step (0.001..10)"}, lo, hi));
    EXPECT_DOUBLE_EQ(lo, 0.001);
    EXPECT_FALSE(option_range({"a", "0", "1: on, 0: off"}, lo, hi));
}

TEST(OptionRange, EveryStatedRangeHoldsItsDefault) {
    // The viewer's sliders start at the default: a range that excludes it is a wrong help.
    for (const SampleInfo& info : all_samples())
        for (const SampleOption& option : info.options) {
            double lo = 0, hi = 0;
            if (!option_range(option, lo, hi)) continue;
            const double value = std::stod(option.default_value);
            EXPECT_GE(value, lo) << info.name << " " << option.name << ": " << option.help;
            EXPECT_LE(value, hi) << info.name << " " << option.name << ": " << option.help;
        }
}

}  // namespace

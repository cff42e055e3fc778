// The Whitted sample (OptiX paper §6.1) on the CPU backend: the golden image (HIPRT rule: a
// pixel differs beyond 10/255, fail beyond 0.3 % of pixels) and physical checks that do not
// depend on the golden: the background is the miss colour, the glass casts a lighter shadow
// than the metal, no exceptions, bad settings are errors.
//
// LUCENT_UPDATE_GOLDEN=1 writes tests/golden/whitted.png from this render instead of comparing.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "lucent/error.h"
#include "samples/sample.h"
#include "samples/whitted/whitted.h"
#include "scene/image_io.h"

namespace lucent::samples {
namespace {

/// CPU by default; LUCENT_TEST_BACKEND=cuda renders on the GPU against the same golden image.
BackendKind lucent_tests_backend() {
    const char* env = std::getenv("LUCENT_TEST_BACKEND");
    return env && std::string(env) == "cuda" ? BackendKind::kCuda : BackendKind::kCpu;
}

constexpr unsigned kGoldenSize = 256;  // modest: the test runs on 2 cores in CI
constexpr double kMaxDifferingFraction = 0.003;

RenderResult render(unsigned size, std::map<std::string, std::string> sets) {
    RenderSettings settings;
    settings.width = settings.height = size;
    settings.backend = lucent_tests_backend();
    settings.sets = std::move(sets);
    return find_sample("whitted").render(settings);
}

/// The golden render (adaptive antialiasing on), made once for the tests that read it.
const RenderResult& golden_render() {
    static const RenderResult result = render(kGoldenSize, {{"aa", "1"}});
    return result;
}

float luminance(float3 c) {
    return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

float3 pixel_at(const scene::Image& image, float2 p) {
    if (!(p.x >= 0.0f && p.y >= 0.0f && p.x < float(image.width) && p.y < float(image.height))) {
        ADD_FAILURE() << "point (" << p.x << ", " << p.y << ") is outside the " << image.width
                      << "x" << image.height << " image";
        return make_float3(0.0f);
    }
    return image.pixels[size_t(p.y) * image.width + size_t(p.x)];
}

/// Centre of a sphere's shadow from the key light: where the line from the light through
/// the sphere's centre meets the floor.
float3 shadow_centre(float3 sphere_center) {
    const WhittedLayout& layout = whitted_layout();
    float3 light = layout.key_light;
    float s = (layout.floor_height - light.y) / (sphere_center.y - light.y);
    float3 p = light + (sphere_center - light) * s;
    p.y = layout.floor_height;
    return p;
}

TEST(Whitted, MatchesGoldenImage) {
    const RenderResult& result = golden_render();
    const std::string golden = std::string(LUCENT_TESTS_DIR) + "/golden/whitted.png";
    const char* update = std::getenv("LUCENT_UPDATE_GOLDEN");
    if (update && std::string(update) == "1") {
        std::filesystem::create_directories(std::filesystem::path(golden).parent_path());
        scene::write_image(golden, result.image);
        GTEST_SKIP() << "LUCENT_UPDATE_GOLDEN=1: wrote " << golden;
    }

    scene::Image8 expected = scene::read_png8(golden);
    scene::Image8 actual{result.image.width, result.image.height, scene::to_srgb8(result.image)};
    ASSERT_EQ(expected.width, actual.width);
    ASSERT_EQ(expected.height, actual.height);
    const size_t differing = scene::count_differing_pixels(actual, expected, 10);
    const size_t allowed = size_t(kMaxDifferingFraction * double(actual.width) * actual.height);
    if (differing > allowed) {
        const std::string written = std::filesystem::absolute("whitted_actual.png").string();
        scene::write_image(written, result.image);
        ADD_FAILURE() << differing << " pixels differ from " << golden << " by more than 10/255 ("
                      << allowed << " allowed); this render is in " << written
                      << " (LUCENT_UPDATE_GOLDEN=1 rewrites the golden if the change is meant)";
    }
}

TEST(Whitted, LaunchRaisesNoExceptions) {
    const RenderResult& result = golden_render();
    EXPECT_EQ(result.report.exception_count(), 0u) << result.report.summary();
    // The GPU adds a "megakernel JIT" stage between compile and launch.
    ASSERT_GE(result.stages.size(), 3u);
    EXPECT_EQ(result.stages.front().name, "scene setup");
    EXPECT_EQ(result.stages[1].name, "compile + accel");
    EXPECT_EQ(result.stages.back().name, "launch");
}

TEST(Whitted, SkyIsExactlyTheMissColour) {
    // Top row, centre: above the glass sphere, every ray of the pixel misses.
    const RenderResult& result = golden_render();
    float3 sky = result.image.pixels[2 * result.image.width + result.image.width / 2];
    float3 background = whitted_layout().background;
    EXPECT_EQ(sky.x, background.x);
    EXPECT_EQ(sky.y, background.y);
    EXPECT_EQ(sky.z, background.z);
}

TEST(Whitted, GlassCastsALighterShadowThanMetal) {
    // Paper §6.1: opaque any-hit stops shadow rays, glass any-hit attenuates them. Compare
    // each shadow's centre with the same floor point rendered without shadow rays, so the
    // checker colour cancels out: lit = albedo (ambient + I cos), shadowed = albedo (ambient
    // + I cos T) with T = 0 under the metal and T = t^4 under the glass shell (its centre
    // line crosses four surfaces at normal incidence). One ray per pixel: both renders see
    // the same floor point.
    constexpr unsigned kSize = 128;
    const RenderResult lit = render(kSize, {{"shadows", "0"}});
    const RenderResult shadowed = render(kSize, {{"shadows", "1"}});
    const WhittedLayout& layout = whitted_layout();

    auto measured_ratio = [&](float3 sphere_center) {
        float2 p = whitted_project(shadow_centre(sphere_center), kSize, kSize);
        float with = luminance(pixel_at(shadowed.image, p));
        float without = luminance(pixel_at(lit.image, p));
        EXPECT_GT(without, 0.0f);
        return with / without;
    };
    auto predicted_ratio = [&](float3 sphere_center, float transmission) {
        float3 p = shadow_centre(sphere_center);
        float cos_theta = normalize(layout.key_light - p).y;  // the floor's normal is +y
        float direct = layout.light_intensity * cos_theta;
        return (layout.ambient + direct * transmission) / (layout.ambient + direct);
    };
    const float metal = measured_ratio(layout.metal_center);
    const float glass = measured_ratio(layout.glass_center);
    const float t = layout.glass_shadow_transmission;
    EXPECT_NEAR(metal, predicted_ratio(layout.metal_center, 0.0f), 0.005f);
    EXPECT_NEAR(glass, predicted_ratio(layout.glass_center, t * t * t * t), 0.005f);
    EXPECT_GT(glass, metal + 0.2f) << "the glass shadow should be clearly lighter";
}

TEST(Whitted, RejectsUnknownSceneNamingTheAcceptedOne) {
    RenderSettings settings;
    settings.width = settings.height = 8;
    settings.backend = lucent_tests_backend();
    settings.scene = "cornell";
    try {
        find_sample("whitted").render(settings);
        FAIL() << "--scene cornell was accepted";
    } catch (const Error& e) {
        std::string message = e.what();
        EXPECT_NE(message.find("cornell"), std::string::npos) << message;
        EXPECT_NE(message.find("whitted"), std::string::npos) << message;
    }
    settings.scene = "whitted";
    EXPECT_NO_THROW(find_sample("whitted").render(settings));
}

TEST(Whitted, RejectsOptionsOutOfRange) {
    EXPECT_THROW(render(8, {{"max_depth", "40"}}), Error);
    EXPECT_THROW(render(8, {{"lights", "0"}}), Error);
    EXPECT_THROW(render(8, {{"aa", "2"}}), Error);
    EXPECT_THROW(render(8, {{"no_such_option", "1"}}), Error);
}

TEST(Whitted, EveryOptionValueRendersWithoutExceptions) {
    for (auto sets : std::vector<std::map<std::string, std::string>>{
             {{"lights", "3"}, {"aa", "1"}}, {{"max_depth", "1"}}, {{"max_depth", "31"}}}) {
        RenderResult result = render(32, sets);
        EXPECT_EQ(result.report.exception_count(), 0u) << result.report.summary();
    }
}

TEST(Whitted, MotionBlursTheMetalSphereAlongItsPath) {
    // motion=1 moves the metal sphere by layout.metal_motion over the shutter [0, 1] and
    // samples a time per camera ray. The point where the sphere's centre ends lies outside
    // the still sphere (|motion| = 1.2 radii) but inside the moving one for the last two
    // thirds of the shutter: the pixels around it change. The sky does not, and the render
    // repeats exactly (times come from a hash of the pixel, not from a clock or a thread).
    constexpr unsigned kSize = 96;
    const RenderResult still = render(kSize, {});
    const RenderResult moving = render(kSize, {{"motion", "1"}});
    const RenderResult again = render(kSize, {{"motion", "1"}});
    EXPECT_EQ(moving.report.exception_count(), 0u) << moving.report.summary();
    ASSERT_EQ(moving.image.pixels.size(), again.image.pixels.size());
    for (size_t i = 0; i < moving.image.pixels.size(); ++i) {
        ASSERT_EQ(moving.image.pixels[i].x, again.image.pixels[i].x) << "pixel " << i;
        ASSERT_EQ(moving.image.pixels[i].y, again.image.pixels[i].y) << "pixel " << i;
        ASSERT_EQ(moving.image.pixels[i].z, again.image.pixels[i].z) << "pixel " << i;
    }
    const float3 sky_still = still.image.pixels[2 * kSize + kSize / 2];
    const float3 sky_moving = moving.image.pixels[2 * kSize + kSize / 2];
    EXPECT_EQ(sky_moving.x, sky_still.x);
    EXPECT_EQ(sky_moving.z, sky_still.z);
    const WhittedLayout& layout = whitted_layout();
    const float2 end = whitted_project(layout.metal_center + layout.metal_motion, kSize, kSize);
    double difference = 0.0;
    int count = 0;
    for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
            const float2 p = make_float2(end.x + float(dx), end.y + float(dy));
            const float3 d = pixel_at(moving.image, p) - pixel_at(still.image, p);
            difference += std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
            ++count;
        }
    EXPECT_GT(difference / count, 0.1) << "the moving sphere does not reach its end point";
    size_t changed = 0;
    for (size_t i = 0; i < still.image.pixels.size(); ++i)
        changed += luminance(still.image.pixels[i]) != luminance(moving.image.pixels[i]);
    // The sphere, its shadow and its reflections: a part of the image, not all of it.
    EXPECT_GT(changed, still.image.pixels.size() / 100);
    EXPECT_LT(changed, still.image.pixels.size() / 3);
}

}  // namespace
}  // namespace lucent::samples

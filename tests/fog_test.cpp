// The fog sample (Sebald §3.1): zero density is exactly no fog; a camera inside uniform fog
// sees Beer-Lambert's law; the march converges as the step shrinks; each TEA key draws its own
// fog; the environment map comes from an .hdr file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <vector>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

#include "samples/sample.h"
#include "tests/test_support.h"

namespace {

using lucent::samples::RenderResult;
using lucent::samples::RenderSettings;

RenderResult render(const std::map<std::string, std::string>& sets, unsigned w = 48,
                    unsigned h = 36) {
    RenderSettings settings;
    settings.width = w;
    settings.height = h;
    settings.backend = lucent_tests::test_backend();  // LUCENT_TEST_BACKEND=cuda: the GPU
    settings.sets = sets;
    return lucent::samples::find_sample("fog").render(settings);
}

float max_difference(const RenderResult& a, const RenderResult& b) {
    float d = 0;
    for (size_t i = 0; i < a.image.pixels.size(); ++i) {
        const float3 e = a.image.pixels[i] - b.image.pixels[i];
        d = std::max({d, std::fabs(e.x), std::fabs(e.y), std::fabs(e.z)});
    }
    return d;
}

double rms_difference(const RenderResult& a, const RenderResult& b) {
    double s = 0;
    for (size_t i = 0; i < a.image.pixels.size(); ++i) {
        const float3 e = a.image.pixels[i] - b.image.pixels[i];
        s += dot(e, e);
    }
    return std::sqrt(s / a.image.pixels.size());
}

TEST(Fog, ZeroDensityIsExactlyNoFog) {
    // The fog's look behind itself is the same ray with the fog ignored.
    const RenderResult none = render({{"fog", "0"}});
    const RenderResult empty = render({{"fog", "1"}, {"density", "0"}});
    EXPECT_EQ(max_difference(none, empty), 0.0f);
    EXPECT_EQ(empty.report.exception_count(), 0u);
}

TEST(Fog, FogChangesThePicture) {
    const RenderResult none = render({{"fog", "0"}});
    const RenderResult foggy = render({});
    EXPECT_GT(rms_difference(none, foggy), 0.02);
    EXPECT_EQ(foggy.report.exception_count(), 0u);
}

TEST(Fog, CameraInsideUniformFogSeesBeerLambert) {
    // The camera 10 from the axis at height 1, inside fog 2 high over the 24 x 24 floor, with
    // uniform density sigma. The centre ray climbs to the look-at point (0, 2, 0) on the fog's
    // top at distance L = sqrt(10^2 + 1^2), then
    // meets the sky: colour = fog (1 - exp(-sigma L)) + sky exp(-sigma L). The paper's fog
    // could not shade rays that start inside the volume.
    const float sigma = 0.05f;
    const std::map<std::string, std::string> view = {{"eye_height", "1"}, {"eye_distance", "10"}};
    auto with = [&](std::map<std::string, std::string> extra) {
        extra.insert(view.begin(), view.end());
        return render(extra, 33, 33);
    };
    const RenderResult sky = with({{"fog", "0"}});
    const RenderResult foggy = with({{"noise", "0"}, {"falloff", "0"}, {"density", "0.05"}});
    const size_t centre = 16 * 33 + 16;
    const float L = std::sqrt(100.0f + 1.0f);
    const float T = std::exp(-sigma * L);
    const float3 fog_colour = make_float3(0.62f, 0.66f, 0.72f);
    const float3 expected = fog_colour * (1.0f - T) + sky.image.pixels[centre] * T;
    EXPECT_NEAR(foggy.image.pixels[centre].x, expected.x, 2e-3f);
    EXPECT_NEAR(foggy.image.pixels[centre].y, expected.y, 2e-3f);
    EXPECT_NEAR(foggy.image.pixels[centre].z, expected.z, 2e-3f);
    EXPECT_EQ(foggy.report.exception_count(), 0u);
}

TEST(Fog, SmallerStepsConverge) {
    const RenderResult fine = render({{"step", "0.005"}});
    const RenderResult medium = render({{"step", "0.05"}});
    const RenderResult coarse = render({{"step", "0.5"}});
    EXPECT_LT(rms_difference(fine, medium), 0.5 * rms_difference(fine, coarse));
    EXPECT_LT(rms_difference(fine, medium), 0.01);
}

TEST(Fog, EachKeyDrawsItsOwnFogAndTheSameKeyTheSame) {
    // Sebald Fig. 4: the key comes from the device identifier and the seed.
    const RenderResult a = render({{"device", "0"}, {"seed", "7"}});
    const RenderResult again = render({{"device", "0"}, {"seed", "7"}});
    const RenderResult other_device = render({{"device", "1"}, {"seed", "7"}});
    const RenderResult other_seed = render({{"device", "0"}, {"seed", "8"}});
    EXPECT_EQ(max_difference(a, again), 0.0f);
    EXPECT_GT(rms_difference(a, other_device), 1e-3);
    EXPECT_GT(rms_difference(a, other_seed), 1e-3);
}

TEST(Fog, EnvironmentMapFromAnHdrFile) {
    namespace fs = std::filesystem;
    const fs::path path =
        fs::temp_directory_path() / ("lucent-fog-env-" + std::to_string(::getpid()) + ".hdr");
    std::vector<float> texels(16 * 8 * 3);
    for (size_t i = 0; i < texels.size(); i += 3) {
        texels[i] = 0.25f;
        texels[i + 1] = 0.5f;
        texels[i + 2] = 2.0f;  // high dynamic range
    }
    ASSERT_TRUE(stbi_write_hdr(path.c_str(), 16, 8, 3, texels.data()));
    const RenderResult r = render({{"fog", "0"}, {"environment", path.string()}});
    const float3 corner = r.image.pixels[0];  // top left: the sky
    EXPECT_NEAR(corner.x, 0.25f, 0.01f);
    EXPECT_NEAR(corner.y, 0.5f, 0.01f);
    EXPECT_NEAR(corner.z, 2.0f, 0.04f);
    fs::remove(path);
    try {
        render({{"environment", "/nonexistent/sky.hdr"}});
        ADD_FAILURE() << "no error";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/sky.hdr"), std::string::npos)
            << e.what();
    }
}

TEST(Fog, ASceneIsNotAccepted) {
    RenderSettings settings;
    settings.width = settings.height = 8;
    settings.backend = lucent::BackendKind::kCpu;
    settings.scene = "cornell";
    EXPECT_THROW(lucent::samples::find_sample("fog").render(settings), std::exception);
}

}  // namespace

// The instant radiosity sample (the seed blog): VPL merging conserves power and places merged
// VPLs at voxel centres; photons carry the light's flux; GI, merging, Russian roulette and
// the VPL display each do what they say.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "samples/sample.h"
#include "samples/radiosity/vpl_grid.h"
#include "scene/scene.h"
#include "tests/test_support.h"

namespace {

using lucent::samples::Bounds3;
using lucent::samples::merge_vpls;
using lucent::samples::RenderResult;
using lucent::samples::RenderSettings;
using radiosity::Vpl;

RenderResult render(const std::map<std::string, std::string>& sets, unsigned size = 48,
                    bool layers = false) {
    RenderSettings settings;
    settings.width = settings.height = size;
    settings.backend = lucent_tests::test_backend();  // LUCENT_TEST_BACKEND=cuda: the GPU
    settings.sets = sets;
    settings.keep_layers = layers;
    return lucent::samples::find_sample("radiosity").render(settings);
}

/// Sum over the pixels, per channel, in double.
struct Sum3 {
    double x = 0, y = 0, z = 0;
};
Sum3 sum(const std::vector<float3>& v) {
    Sum3 s;
    for (const float3& p : v) {
        s.x += p.x;
        s.y += p.y;
        s.z += p.z;
    }
    return s;
}
double total(const lucent::scene::Image& image) {
    const Sum3 s = sum(image.pixels);
    return s.x + s.y + s.z;
}

float brightness(const RenderResult& r, float fx, float fy) {
    const float3 p =
        r.image.pixels[size_t(fy * r.image.height) * r.image.width + size_t(fx * r.image.width)];
    return p.x + p.y + p.z;
}

TEST(VplGrid, MergingConservesPowerAndUsesVoxelCentres) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<Vpl> vpls;
    for (int i = 0; i < 5000; ++i) {
        const float3 n = normalize(make_float3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f));
        vpls.push_back({make_float3(10 * u(rng), 20 * u(rng), 30 * u(rng)), n,
                        make_float3(u(rng), u(rng), u(rng))});
    }
    vpls.push_back({make_float3(5, 5, 5), make_float3(0, 1, 0), make_float3(0.0f)});  // empty slot
    vpls.push_back(
        {make_float3(-4, 50, 5), make_float3(0, 1, 0), make_float3(1, 2, 3)});  // outside
    const Bounds3 bounds{make_float3(0, 0, 0), make_float3(10, 20, 30)};
    const std::vector<Vpl> merged = merge_vpls(vpls, bounds, 4);
    EXPECT_LE(merged.size(), 64u);
    EXPECT_GT(merged.size(), 32u) << "5000 random VPLs fill most of 64 voxels";
    const Sum3 before = sum([&] {
        std::vector<float3> p;
        for (const Vpl& v : vpls) p.push_back(v.power);
        return p;
    }());
    const Sum3 after = sum([&] {
        std::vector<float3> p;
        for (const Vpl& v : merged) p.push_back(v.power);
        return p;
    }());
    EXPECT_NEAR(after.x, before.x, 1e-4 * before.x);
    EXPECT_NEAR(after.y, before.y, 1e-4 * before.y);
    EXPECT_NEAR(after.z, before.z, 1e-4 * before.z);
    for (const Vpl& v : merged) {
        // Centres of 2.5 x 5 x 7.5 voxels.
        EXPECT_FLOAT_EQ(std::fmod(v.position.x, 2.5f), 1.25f);
        EXPECT_FLOAT_EQ(std::fmod(v.position.y, 5.0f), 2.5f);
        EXPECT_FLOAT_EQ(std::fmod(v.position.z, 7.5f), 3.75f);
        const float n = length(v.normal);
        EXPECT_TRUE(n == 0.0f || std::fabs(n - 1.0f) < 1e-5f) << "unit or isotropic";
    }
}

TEST(VplGrid, OneVoxelKeepsTheMeanNormalOrNone) {
    const Bounds3 bounds{make_float3(0.0f), make_float3(1.0f)};
    const std::vector<Vpl> same =
        merge_vpls({{make_float3(0.2f), make_float3(0, 1, 0), make_float3(1.0f)},
                    {make_float3(0.7f), make_float3(0, 1, 0), make_float3(2.0f)}},
                   bounds, 1);
    ASSERT_EQ(same.size(), 1u);
    EXPECT_FLOAT_EQ(same[0].normal.y, 1.0f);
    EXPECT_FLOAT_EQ(same[0].power.x, 3.0f);
    EXPECT_FLOAT_EQ(same[0].position.x, 0.5f);
    const std::vector<Vpl> opposite =
        merge_vpls({{make_float3(0.2f), make_float3(0, 1, 0), make_float3(1.0f)},
                    {make_float3(0.7f), make_float3(0, -1, 0), make_float3(1.0f)}},
                   bounds, 1);
    ASSERT_EQ(opposite.size(), 1u);
    EXPECT_EQ(length(opposite[0].normal), 0.0f) << "cancelling normals: isotropic";
}

TEST(Radiosity, PhotonsCarryTheLightsFluxTimesTheAlbedoTheyMeet) {
    // One bounce: the VPLs' power sums to the light's flux pi L A times the albedo of the
    // surface each photon first hits, so per channel it is at most the largest albedo times
    // the flux. The box is open towards the camera, and photons leaving through it carry
    // nothing; the walls still catch most of them.
    const lucent::scene::Scene scene = lucent::scene::load_scene("cornell");
    const auto& light = scene.area_lights.at(0);
    const float3 flux = light.emission * (float(M_PI) * length(cross(light.edge1, light.edge2)));
    float3 hi = make_float3(0.0f);
    for (const auto& m : scene.materials)
        if (max_component(m.emission) == 0) hi = fmaxf(hi, m.diffuse);
    const RenderResult r = render({{"bounces", "1"}, {"photons", "4096"}}, 8, true);
    const Sum3 s = sum(r.layers.at("vpl_power").pixels);
    EXPECT_LE(s.x, hi.x * flux.x);
    EXPECT_LE(s.y, hi.y * flux.y);
    EXPECT_LE(s.z, hi.z * flux.z);
    EXPECT_GT(s.y, 0.4 * hi.y * flux.y);
    // Four times the photons: the same power (each carries a quarter as much).
    const RenderResult more = render({{"bounces", "1"}, {"photons", "16384"}}, 8, true);
    EXPECT_NEAR(sum(more.layers.at("vpl_power").pixels).y / s.y, 1.0, 0.03);
}

TEST(Radiosity, MergedVplsConserveTheTotalPower) {
    const RenderResult r = render({{"merge", "1"}, {"grid", "8"}}, 8, true);
    const lucent::scene::Image& raw = r.layers.at("vpl_power");
    const lucent::scene::Image& merged = r.layers.at("merged_vpl_power");
    EXPECT_LT(merged.width, raw.width / 2) << "merging reduces the count";
    EXPECT_NEAR(total(merged), total(raw), 1e-4 * total(raw));
}

TEST(Radiosity, GlobalIlluminationLightsWhatTheLightCannotSee) {
    // The short block's front face is turned away from the ceiling light.
    const RenderResult direct = render({{"gi", "0"}});
    const RenderResult global = render({{"gi", "1"}});
    EXPECT_EQ(brightness(direct, 0.6f, 0.9f), 0.0f);
    EXPECT_GT(brightness(global, 0.6f, 0.9f), 1e-3f);
    EXPECT_GT(total(global.image), 1.1 * total(direct.image));
    EXPECT_EQ(global.report.exception_count(), 0u);
}

TEST(Radiosity, MergingChangesThePictureLittle) {
    const RenderResult all = render({{"merge", "0"}});
    const RenderResult merged = render({{"merge", "1"}});
    EXPECT_NEAR(total(merged.image) / total(all.image), 1.0, 0.05);
}

TEST(Radiosity, RussianRouletteKeepsTheMeanPower) {
    const RenderResult every =
        render({{"roulette", "0"}, {"bounces", "4"}, {"photons", "16384"}}, 8, true);
    const RenderResult roulette =
        render({{"roulette", "1"}, {"bounces", "4"}, {"photons", "16384"}}, 8, true);
    EXPECT_NEAR(total(roulette.layers.at("vpl_power")) / total(every.layers.at("vpl_power")), 1.0,
                0.03);
}

TEST(Radiosity, ShowVplsDrawsDots) {
    const RenderResult plain = render({{"gi", "0"}});
    const RenderResult dots = render({{"gi", "0"}, {"show_vpls", "1"}});
    size_t changed = 0;
    for (size_t i = 0; i < plain.image.pixels.size(); ++i) {
        const float3 d = plain.image.pixels[i] - dots.image.pixels[i];
        changed += dot(d, d) > 1e-6f;
    }
    EXPECT_GT(changed, 20u);
    EXPECT_LT(changed, plain.image.pixels.size() / 2);
}

TEST(Radiosity, SceneWithoutAnAreaLightIsAClearError) {
    RenderSettings settings;
    settings.width = settings.height = 8;
    settings.backend = lucent_tests::test_backend();  // LUCENT_TEST_BACKEND=cuda: the GPU
    settings.scene = "cornell-point";
    try {
        lucent::samples::find_sample("radiosity").render(settings);
        ADD_FAILURE() << "no error";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("no area light"), std::string::npos) << e.what();
    }
}

}  // namespace

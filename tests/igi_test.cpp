// The IGI sample, canonical form (seed §4): VPLs light what the point light cannot see, and
// Eq. (1)'s bounded geometry term removes VPLs closer than its bounding distance.
#include <gtest/gtest.h>

#include "samples/igi/igi.h"
#include "samples/igi/igi_programs.h"

namespace {

using lucent::samples::RenderResult;
using lucent::samples::RenderSettings;

RenderResult render(const std::map<std::string, std::string>& sets) {
    RenderSettings settings;
    settings.width = settings.height = 64;
    settings.backend = lucent::BackendKind::kCpu;
    settings.sets = sets;
    return lucent::samples::igi_sample_info().render(settings);
}

float brightness(const RenderResult& r, float fx, float fy) {
    const float3 p =
        r.image.pixels[size_t(fy * r.image.height) * r.image.width + size_t(fx * r.image.width)];
    return p.x + p.y + p.z;
}

TEST(Igi, SmoothingIsZeroThenQuadraticThenOne) {
    EXPECT_EQ(igi::smoothing(1.0f, 2.0f, 0.5f), 0.0f);
    EXPECT_FLOAT_EQ(igi::smoothing(1.0f, 2.0f, 1.5f), 0.25f);
    EXPECT_EQ(igi::smoothing(1.0f, 2.0f, 2.5f), 1.0f);
}

TEST(Igi, HaltonIsTheRadicalInverse) {
    EXPECT_FLOAT_EQ(igi::halton(1, 2), 0.5f);
    EXPECT_FLOAT_EQ(igi::halton(3, 2), 0.75f);
    EXPECT_FLOAT_EQ(igi::halton(2, 3), 2.0f / 3.0f);
}

TEST(Igi, VplsLightWhatThePointLightCannotSee) {
    // The short block's front face is turned away from the ceiling light: black with direct
    // light only (min_d = 10 scene sizes bounds away every VPL), lit by the VPLs otherwise.
    const RenderResult direct_only = render({{"min_d", "10"}});
    const RenderResult global = render({{"vpls", "180"}, {"min_d", "0.05"}});
    EXPECT_EQ(brightness(direct_only, 0.6f, 0.85f), 0.0f);
    EXPECT_GT(brightness(global, 0.6f, 0.85f), 1e-4f);
    EXPECT_EQ(global.report.exception_count(), 0u);
}

TEST(Igi, ImperfectVisibilityTracesTheBoxesGraph) {
    // Seed §4.1: VPL shadow rays against one box per triangle, a second root and ray type.
    // Boxes hide at least as much as the triangles in them, never more light arrives.
    const RenderResult exact = render({{"imperfect_visibility", "0"}});
    const RenderResult boxes = render({{"imperfect_visibility", "1"}});
    EXPECT_EQ(boxes.report.exception_count(), 0u);
    double sum_exact = 0, sum_boxes = 0;
    for (size_t i = 0; i < exact.image.pixels.size(); ++i) {
        sum_exact += exact.image.pixels[i].x + exact.image.pixels[i].y + exact.image.pixels[i].z;
        sum_boxes += boxes.image.pixels[i].x + boxes.image.pixels[i].y + boxes.image.pixels[i].z;
    }
    EXPECT_LE(sum_boxes, sum_exact * 1.0001);
    EXPECT_GT(sum_boxes, 0.8 * sum_exact) << "the boxes approximate the scene";
    EXPECT_GT(brightness(boxes, 0.6f, 0.85f), 0.0f) << "VPL light still arrives";
}

TEST(Igi, SceneWithoutPointLightsIsAClearError) {
    RenderSettings settings;
    settings.width = settings.height = 8;
    settings.backend = lucent::BackendKind::kCpu;
    settings.scene = "cornell";  // area light only
    try {
        lucent::samples::igi_sample_info().render(settings);
        FAIL();
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("point lights"), std::string::npos) << e.what();
    }
}

}  // namespace

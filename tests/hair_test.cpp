// The hair sample (samples/hair): its image shows the hair where the strands project, every
// curve type renders, light linking brightens only what the hair shadowed from the key light
// (and, with direct light only, leaves every pixel whose shadow rays cannot reach the hair
// bit for bit the same), the viewer's first frame is the render's, the images repeat, and
// bad options are errors. LUCENT_TEST_BACKEND=cuda runs it on the GPU.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "samples/common/camera.h"
#include "samples/hair/hair_scene.h"
#include "samples/sample.h"
#include "samples/scene_setup.h"
#include "samples/settings_error.h"
#include "tests/test_support.h"

namespace {

using lucent::samples::RenderResult;
using lucent::samples::RenderSettings;
using lucent::samples::SettingsError;

constexpr unsigned kWidth = 128, kHeight = 72;

RenderSettings settings_for(unsigned spp, const std::map<std::string, std::string>& sets) {
    RenderSettings settings;
    settings.width = kWidth;
    settings.height = kHeight;
    settings.backend = lucent_tests::test_backend();  // LUCENT_TEST_BACKEND=cuda: the GPU
    settings.threads = 2;
    settings.spp = spp;
    settings.sets = sets;
    return settings;
}

RenderResult render(unsigned spp, const std::map<std::string, std::string>& sets = {}) {
    return lucent::samples::find_sample("hair").render(settings_for(spp, sets));
}

float luminance(float3 c) {
    return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

/// The sample's scene as data (the default shape) and its pinhole camera for our image.
struct Layout {
    lucent::samples::HairSceneData data = lucent::samples::make_hair_scene({});
    sample_common::PinholeCamera camera =
        lucent::samples::pinhole_camera(data.meshes.camera, float(kWidth) / float(kHeight));
};

/// Where point p lands in the image (pixel coordinates, row 0 at the top); false when it is
/// behind the camera.
bool project(const sample_common::PinholeCamera& c, float3 p, float& x, float& y) {
    const float3 d = p - c.eye;
    const float depth = dot(d, c.W);
    if (depth <= 0.0f) return false;
    const float sx = dot(d, c.U) / (dot(c.U, c.U) * depth);
    const float sy = dot(d, c.V) / (dot(c.V, c.V) * depth);
    x = 0.5f * (sx + 1.0f) * kWidth;
    y = 0.5f * (1.0f - sy) * kHeight;
    return true;
}

/// The distance from `c` to the segment from a to b.
float distance_to_segment(float3 c, float3 a, float3 b) {
    const float3 ab = b - a;
    const float s = std::clamp(dot(c - a, ab) / dot(ab, ab), 0.0f, 1.0f);
    return length(a + s * ab - c);
}

/// Whether the line from `origin` along the unit `direction` passes within `radius` of `c`.
bool passes_within(float3 origin, float3 direction, float3 c, float radius) {
    const float3 to = c - origin;
    const float along = std::max(0.0f, dot(to, direction));
    return length(to - along * direction) < radius;
}

/// How far any hair reaches from the head's centre: roots at 1.002 radii, then at most 14
/// steps of 0.07 (a cubic strand's 15 points; the curve stays in their hull), plus the root
/// radius 0.004, on the unit head; a little more for safety.
float hair_reach(const Layout& l) {
    return l.data.head_radius * 2.0f;
}

/// Pixels that see the ground at every corner, no sphere, head or hair near their rays, and
/// whose ground points see every point of a 9 x 9 grid on the key light past the hair's
/// reach by a margin: the hair cannot shadow the key light there.
std::vector<bool> unshadowable_ground(const Layout& l) {
    const lucent::scene::AreaLight key = l.data.meshes.area_lights.at(0);
    const float ground = l.data.head_center.y - l.data.head_radius;
    const float reach = hair_reach(l);
    std::vector<bool> safe(size_t(kWidth) * kHeight, false);
    for (unsigned y = 0; y < kHeight; ++y)
        for (unsigned x = 0; x < kWidth; ++x) {
            bool ok = true;
            for (int corner = 0; corner < 4 && ok; ++corner) {
                const float sx = 2.0f * float(x + (corner & 1)) / kWidth - 1.0f;
                const float sy = 1.0f - 2.0f * float(y + (corner >> 1)) / kHeight;
                const float3 dir = sample_common::camera_direction(l.camera, sx, sy);
                ok = dir.y < 0.0f &&
                     !passes_within(l.camera.eye, dir, l.data.head_center, reach + 0.1f);
                for (const auto& sphere : l.data.spheres)
                    ok = ok &&
                         !passes_within(l.camera.eye, dir, sphere.center, sphere.radius + 0.05f);
                if (!ok) break;
                const float t = (ground - l.camera.eye.y) / dir.y;
                const float3 g = l.camera.eye + t * dir;
                ok = std::fabs(g.x) < 9.0f && std::fabs(g.z) < 9.0f;
                // Light points 0.2 apart: a segment to a point between them passes within 0.1
                // of one to a grid point.
                for (int i = 0; i <= 8 && ok; ++i)
                    for (int j = 0; j <= 8 && ok; ++j) {
                        const float3 q =
                            key.corner + (i / 8.0f) * key.edge1 + (j / 8.0f) * key.edge2;
                        ok = distance_to_segment(l.data.head_center, g, q) > reach + 0.15f;
                    }
            }
            safe[size_t(y) * kWidth + x] = ok;
        }
    return safe;
}

TEST(Hair, ImageShowsTheHairWhereTheStrandsProject) {
    const Layout l;
    const RenderResult with = render(4);
    const RenderResult without = render(4, {{"strands", "0"}});
    ASSERT_EQ(with.image.width, kWidth);
    ASSERT_EQ(with.report.exception_count(), 0u) << with.report.summary();
    double sum = 0;
    for (const float3& p : with.image.pixels) sum += luminance(p);
    EXPECT_GT(sum / with.image.pixels.size(), 0.05) << "the image is (nearly) black";

    // The pixels holding a strand's control point, not behind a sphere: auburn with hair.
    std::vector<bool> hair(size_t(kWidth) * kHeight, false);
    for (const float3& v : l.data.hair.vertices) {
        float x, y;
        if (!project(l.camera, v, x, y) || x < 0 || y < 0 || x >= kWidth || y >= kHeight) continue;
        const float3 dir = normalize(v - l.camera.eye);
        bool hidden = false;
        for (const auto& sphere : l.data.spheres)
            hidden =
                hidden || passes_within(l.camera.eye, dir, sphere.center, sphere.radius + 0.05f);
        if (!hidden) hair[size_t(y) * kWidth + size_t(x)] = true;
    }
    unsigned pixels = 0, changed = 0;
    double red_with = 0, blue_with = 0, red_without = 0, blue_without = 0;
    for (size_t i = 0; i < hair.size(); ++i) {
        if (!hair[i]) continue;
        ++pixels;
        const float3 a = with.image.pixels[i], b = without.image.pixels[i];
        changed += std::fabs(luminance(a) - luminance(b)) > 0.05f * luminance(b) ||
                   std::fabs(a.z - b.z) > 0.05f * b.z;
        red_with += a.x, blue_with += a.z, red_without += b.x, blue_without += b.z;
    }
    ASSERT_GT(pixels, kWidth * kHeight / 20) << "the strands should cover a good part of the image";
    EXPECT_GT(changed, 0.8 * pixels) << changed << " of " << pixels << " hair pixels changed";
    // Auburn hair (Kd 0.42, 0.17, 0.06) is much redder than the head, ground and sky it hides.
    EXPECT_GT(red_with / blue_with, 1.5 * (red_without / blue_without));
}

TEST(Hair, EveryCurveTypeRendersTheHair) {
    const RenderResult bald = render(1, {{"strands", "0"}, {"max_depth", "2"}});
    for (const char* type : {"linear", "quadratic", "cubic", "catmull-rom"}) {
        const RenderResult r = render(1, {{"curve_type", type}, {"max_depth", "2"}});
        ASSERT_EQ(r.report.exception_count(), 0u) << type << ": " << r.report.summary();
        unsigned differ = 0;
        for (size_t i = 0; i < r.image.pixels.size(); ++i)
            differ += length(r.image.pixels[i] - bald.image.pixels[i]) > 0.02f;
        EXPECT_GT(differ, r.image.pixels.size() / 20) << type;
    }
}

TEST(Hair, LightLinkingBrightensOnlyWhatTheHairShadowed) {
    const Layout l;
    // Two path segments: next-event estimation at the camera's hit only, so a pixel changes
    // only where a shadow ray from that hit to the key light could meet the hair.
    const RenderResult linked = render(4, {{"light_linking", "1"}, {"max_depth", "2"}});
    const RenderResult unlinked = render(4, {{"light_linking", "0"}, {"max_depth", "2"}});
    const std::vector<bool> safe = unshadowable_ground(l);
    unsigned safe_count = 0, safe_changed = 0, darker = 0, brighter = 0;
    for (size_t i = 0; i < safe.size(); ++i) {
        const float3 a = linked.image.pixels[i], b = unlinked.image.pixels[i];
        // The same random numbers either way: a shadow ray the hair blocked only adds light.
        darker += a.x < b.x || a.y < b.y || a.z < b.z;
        brighter += luminance(a) > 1.1f * luminance(b) + 1e-4f;
        if (!safe[i]) continue;
        ++safe_count;
        safe_changed += a.x != b.x || a.y != b.y || a.z != b.z;
    }
    EXPECT_EQ(darker, 0u) << "light linking darkened pixels";
    EXPECT_GT(brighter, kWidth * kHeight / 50) << "light linking should light what hair shadowed";
    ASSERT_GT(safe_count, kWidth * kHeight / 10) << "the test's safe ground region is too small";
    EXPECT_EQ(safe_changed, 0u) << "pixels the hair cannot shadow changed (of " << safe_count
                                << ")";
}

TEST(Hair, LightLinkingWithoutHairChangesNothing) {
    // No instance has the hair's mask: the key light's mask leaves nothing out.
    const RenderResult linked = render(2, {{"strands", "0"}, {"light_linking", "1"}});
    const RenderResult unlinked = render(2, {{"strands", "0"}, {"light_linking", "0"}});
    ASSERT_EQ(linked.image.pixels.size(), unlinked.image.pixels.size());
    for (size_t i = 0; i < linked.image.pixels.size(); ++i)
        ASSERT_EQ(length(linked.image.pixels[i] - unlinked.image.pixels[i]), 0.0f) << "pixel " << i;
}

TEST(Hair, RendersTheSameImageTwice) {
    const RenderResult a = render(2), b = render(2);
    const RenderResult other_seed = render(2, {{"seed", "5"}});
    ASSERT_EQ(a.image.pixels.size(), b.image.pixels.size());
    unsigned seed_differs = 0;
    for (size_t i = 0; i < a.image.pixels.size(); ++i) {
        ASSERT_EQ(length(a.image.pixels[i] - b.image.pixels[i]), 0.0f) << "pixel " << i;
        seed_differs += length(a.image.pixels[i] - other_seed.image.pixels[i]) > 0.0f;
    }
    EXPECT_GT(seed_differs, a.image.pixels.size() / 2) << "another seed draws other paths";
}

TEST(Hair, ViewerSessionStartsWithTheRendersImage) {
    const RenderSettings settings = settings_for(1, {});
    const auto& sample = lucent::samples::find_sample("hair");
    const RenderResult rendered = sample.render(settings);
    auto session = sample.open(settings);
    ASSERT_TRUE(session->progressive());
    const lucent::samples::FrameResult first = session->frame();
    EXPECT_EQ(first.samples, 1u);
    ASSERT_EQ(first.image.pixels.size(), rendered.image.pixels.size());
    for (size_t i = 0; i < first.image.pixels.size(); ++i)
        ASSERT_EQ(length(first.image.pixels[i] - rendered.image.pixels[i]), 0.0f) << "pixel " << i;
    // Light linking and the exposure change in place (the accumulation restarts); the
    // scene's shape needs a new session.
    EXPECT_TRUE(session->set_option("light_linking", "0"));
    EXPECT_EQ(session->frame().samples, 1u);
    EXPECT_EQ(session->frame().samples, 2u);
    EXPECT_TRUE(session->set_option("exposure", "2"));
    EXPECT_FALSE(session->set_option("strands", "100"));
    EXPECT_FALSE(session->set_option("curve_type", "linear"));
    EXPECT_THROW(session->set_option("curve_type", "spline"), SettingsError);
    // Relinked in place, the session's frame is the unlinked render's.
    auto relinked = sample.open(settings);
    ASSERT_TRUE(relinked->set_option("light_linking", "0"));
    const lucent::samples::FrameResult frame = relinked->frame();
    const RenderResult unlinked = sample.render(settings_for(1, {{"light_linking", "0"}}));
    for (size_t i = 0; i < frame.image.pixels.size(); ++i)
        ASSERT_EQ(length(frame.image.pixels[i] - unlinked.image.pixels[i]), 0.0f) << "pixel " << i;
}

std::string error_of(const RenderSettings& settings) {
    try {
        lucent::samples::find_sample("hair").render(settings);
    } catch (const SettingsError& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(Hair, BadOptionsAreErrors) {
    EXPECT_THAT(
        error_of(settings_for(1, {{"curve_type", "cubik"}})),
        ::testing::AllOf(::testing::HasSubstr("curve_type=cubik"), ::testing::HasSubstr("cubic"),
                         ::testing::HasSubstr("catmull-rom")));
    EXPECT_THAT(error_of(settings_for(1, {{"strands", "-1"}})), ::testing::HasSubstr("strands"));
    EXPECT_THAT(error_of(settings_for(1, {{"strands", "300000"}})),
                ::testing::HasSubstr("strands"));
    EXPECT_THAT(error_of(settings_for(1, {{"light_linking", "2"}})),
                ::testing::HasSubstr("light_linking"));
    EXPECT_THAT(error_of(settings_for(1, {{"hair_colour", "red"}})),
                ::testing::HasSubstr("hair_colour"));
    RenderSettings with_scene = settings_for(1, {});
    with_scene.scene = "cornell";
    EXPECT_THAT(error_of(with_scene), ::testing::HasSubstr("renders its own scene"));
    RenderSettings with_camera = settings_for(1, {});
    with_camera.scene_camera = 1;
    EXPECT_THAT(error_of(with_camera), ::testing::HasSubstr("--camera 1"));
}

}  // namespace

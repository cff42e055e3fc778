// Glass in IGI's direct + specular tree (igi::dielectric): the reflected and transmitted
// branches with their Fresnel weights, the 1 / eta^2 of radiance crossing into another
// medium, total internal reflection and the tree's depth bound, against closed forms and the
// path tracer. The scenes are lit by an emitter seen through the glass, so nothing but the
// tree decides a pixel.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "samples/sample.h"
#include "test_support.h"

namespace {

using lucent::samples::RenderResult;
using lucent::samples::RenderSettings;
using Sets = std::map<std::string, std::string>;

RenderResult render(const std::string& sample, const std::string& scene, unsigned size,
                    const Sets& sets, unsigned spp = 0) {
    RenderSettings settings;
    settings.width = settings.height = size;
    settings.backend = lucent_tests::test_backend();  // LUCENT_TEST_BACKEND=cuda: the GPU
    settings.threads = 2;
    settings.scene = scene;
    settings.sets = sets;
    if (spp) settings.spp = spp;
    return lucent::samples::find_sample(sample).render(settings);
}

/// A box [lo, hi] as OBJ text, its faces wound outwards (the side a dielectric's normal
/// calls outside).
std::string obj_box(float3 lo, float3 hi) {
    std::string s;
    for (int i = 0; i < 8; ++i) {
        const float3 p = make_float3((i == 1 || i == 2 || i == 5 || i == 6) ? hi.x : lo.x,
                                     (i == 2 || i == 3 || i == 6 || i == 7) ? hi.y : lo.y,
                                     i >= 4 ? hi.z : lo.z);
        s += "v " + std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + "\n";
    }
    return s + "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";
}

/// Unpolarised Fresnel reflectance from n1 into n2 at incidence angle theta, from Snell's
/// law and the Fresnel equations (Born and Wolf §1.5.2), written independently of
/// samples/common/fresnel.h; 1 beyond the critical angle.
double fresnel(double theta, double n1, double n2) {
    const double s = n1 / n2 * std::sin(theta);
    if (s >= 1) return 1;
    const double ci = std::cos(theta), ct = std::sqrt(1 - s * s);
    const double rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    const double rp = (n1 * ct - n2 * ci) / (n1 * ct + n2 * ci);
    return 0.5 * (rs * rs + rp * rp);
}

float3 mean(const RenderResult& r, int x0, int y0, int x1, int y1) {
    float3 sum = make_float3(0.0f);
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) sum += r.image.pixels[size_t(y) * r.image.width + size_t(x)];
    return sum / float((x1 - x0) * (y1 - y0));
}

class GlassScenes : public lucent_tests::TempDirTest {
  protected:
    /// A JSON scene of an emitter (radiance 1, black itself) and a glass box of index 1.5.
    std::string scene(const std::string& name, const std::string& camera, float3 lo, float3 hi,
                      const std::string& emitter_obj) {
        write(name + "_glass.obj", obj_box(lo, hi));
        write(name + "_emitter.obj", emitter_obj);
        return write(name + ".json", R"({"camera": )" + camera + R"(,
            "materials": [{"name": "glass", "type": "dielectric", "ior": 1.5},
                          {"name": "emitter", "diffuse": [0, 0, 0], "emission": [1, 1, 1]}],
            "meshes": [{"file": ")" + name + R"(_glass.obj", "material": "glass"},
                       {"file": ")" + name + R"(_emitter.obj", "material": "emitter"}]})");
    }
};

TEST_F(GlassScenes, IgiSeesAnEmitterThroughASlabAsFresnelSays) {
    // A 0.4 thick slab between the camera and an emitter, seen head on: at normal incidence
    // each face transmits 1 - F, F = ((1.5 - 1) / 2.5)^2 = 0.04, and radiance is multiplied
    // by 1 / 1.5^2 going in and 1.5^2 coming out. A tree of depth 3 reaches the emitter
    // through the two faces only: (1 - F)^2. Depth 8 adds the paths reflected inside the
    // slab once and twice: (1 - F)^2 (1 + F^2 + F^4).
    const std::string slab = scene(
        "slab", R"({"eye": [0, 0, 5], "look": [0, 0, 0], "fov": 30})", make_float3(-1, -1, -0.2f),
        make_float3(1, 1, 0.2f), "v -6 -6 -3\nv 6 -6 -3\nv 6 6 -3\nv -6 6 -3\nf 1 2 3 4\n");
    const double f = 0.04, through = (1 - f) * (1 - f);
    const RenderResult shallow = render("igi", slab, 48, {{"max_depth", "3"}});
    const RenderResult deep = render("igi", slab, 48, {{"max_depth", "8"}});
    // The middle 4 x 4 pixels look within 0.3 degrees of the normal: F is 0.04 to 1e-6.
    EXPECT_NEAR(mean(shallow, 22, 22, 26, 26).x, through, 1e-4);
    EXPECT_NEAR(mean(deep, 22, 22, 26, 26).x, through * (1 + f * f + f * f * f * f), 1e-4);
    // The corners miss the slab and see the emitter itself.
    EXPECT_NEAR(mean(deep, 0, 0, 2, 2).x, 1.0, 1e-5);

    // The path tracer chooses one branch per sample with probability F and gets the same in
    // expectation: over the slab (the middle 24 x 24 pixels, up to 7 degrees off the normal)
    // within 1 % (64 samples of 576 pixels, each 1 with probability about 0.92: 0.1 % noise).
    for (const char* depth : {"3", "8"}) {
        const RenderResult igi = render("igi", slab, 48, {{"max_depth", depth}});
        const RenderResult pt =
            render("pathtracer", slab, 48, {{"max_depth", depth}, {"rr_depth", "16"}}, 64);
        const float a = mean(igi, 12, 12, 36, 36).x, b = mean(pt, 12, 12, 36, 36).x;
        EXPECT_NEAR(a, b, 0.01 * b) << "max_depth " << depth;
    }
}

TEST_F(GlassScenes, IgiReflectsTotallyInsideGlassBeyondTheCriticalAngle) {
    // The camera inside a glass block looks out through its face z = 1 at an emitter beyond
    // it, 120 degrees wide. Below the critical angle asin(1 / 1.5) = 41.8 degrees a pixel is
    // (1 - F) x 1.5^2 (radiance is 1.5^2 larger inside the denser medium); beyond it the face
    // reflects everything back into the block, and a tree of depth 2 ends on the block's far
    // faces: black.
    const std::string inside =
        scene("inside", R"({"eye": [0, 0, 0], "look": [0, 0, 1], "fov": 120})",
              make_float3(-3, -3, -3), make_float3(3, 3, 1),
              "v -50 -50 2\nv -50 50 2\nv 50 50 2\nv 50 -50 2\nf 1 2 3 4\n");
    const unsigned n = 64;
    const RenderResult igi = render("igi", inside, n, {{"max_depth", "2"}});
    const double h = std::tan(60.0 * 3.14159265358979 / 180.0);
    const double critical = std::asin(1 / 1.5);
    size_t transmitted = 0, reflected = 0;
    for (unsigned y = 0; y < n; ++y)
        for (unsigned x = 0; x < n; ++x) {
            // The pixel centre's angle to the face's normal (samples/common/camera.h).
            const double sx = 2.0 * (x + 0.5) / n - 1, sy = 1 - 2.0 * (y + 0.5) / n;
            const double theta = std::atan(h * std::sqrt(sx * sx + sy * sy));
            const float value = igi.image.pixels[size_t(y) * n + x].x;
            if (theta < critical - 0.02) {
                const double expected = (1 - fresnel(theta, 1.5, 1.0)) * 1.5 * 1.5;
                EXPECT_NEAR(value, expected, 1e-3 * expected) << x << ", " << y;
                ++transmitted;
            } else if (theta > critical + 0.02) {
                EXPECT_EQ(value, 0.0f) << x << ", " << y << ": total internal reflection";
                ++reflected;
            }
        }
    EXPECT_GT(transmitted, 500u);
    EXPECT_GT(reflected, 1000u);

    // The path tracer agrees on both sides of the critical angle: the middle (transmitted)
    // and a corner (reflected).
    const RenderResult pt = render("pathtracer", inside, n, {{"max_depth", "2"}}, 64);
    const float a = mean(igi, 24, 24, 40, 40).x, b = mean(pt, 24, 24, 40, 40).x;
    EXPECT_NEAR(a, b, 0.01 * b);
    EXPECT_EQ(mean(pt, 0, 0, 8, 8).x, 0.0f);
}

}  // namespace

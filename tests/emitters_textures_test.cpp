// Emissive triangles as area lights and map_Kd textures in every sample that lights
// surfaces, checked against values, not looks: the radiance of a floor under a square
// emitter against the closed-form irradiance of a rectangle, and a two-colour texture on a
// quad. Also: a scene without a camera gets one that frames it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "samples/sample.h"
#include "scene/image_io.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;
using lucent::samples::RenderResult;
using lucent::samples::RenderSettings;

/// A folder of this test's own, removed at the end.
struct SceneDir {
    fs::path path;
    SceneDir() {
        path = fs::temp_directory_path() /
               ("lucent-emitters-" + std::to_string(::getpid()) + "-" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(path);
    }
    ~SceneDir() { fs::remove_all(path); }
    std::string file(const std::string& name) const { return (path / name).string(); }
};

RenderResult render(const std::string& sample, const std::string& scene, unsigned size,
                    const std::map<std::string, std::string>& sets) {
    RenderSettings settings;
    settings.width = settings.height = size;
    settings.backend = lucent_tests::test_backend();  // LUCENT_TEST_BACKEND=cuda: the GPU
    settings.threads = 2;
    settings.scene = scene;
    for (auto& [k, v] : sets) {
        if (k == "spp")
            settings.spp = unsigned(std::stoul(v));  // samples per pixel is a setting of its own
        else
            settings.sets[k] = v;
    }
    return lucent::samples::find_sample(sample).render(settings);
}

/// The mean of the (2r+1)^2 pixels around the image centre (a block small enough that the
/// floor's irradiance is flat across it: the closed form is for the centre).
float3 centre_mean(const RenderResult& r, int radius) {
    float3 sum = make_float3(0.0f);
    const int cx = int(r.image.width) / 2, cy = int(r.image.height) / 2;
    for (int y = cy - radius; y <= cy + radius; ++y)
        for (int x = cx - radius; x <= cx + radius; ++x)
            sum += r.image.pixels[size_t(y) * r.image.width + size_t(x)];
    return sum / float((2 * radius + 1) * (2 * radius + 1));
}

/// Irradiance at a point under the corner of an a x b rectangle at height h that emits
/// radiance 1: pi times the form factor of the corner rectangle (Howell's catalogue of
/// configuration factors, C-11).
double corner_irradiance(double a, double b, double h) {
    const double X = a / h, Y = b / h, sx = std::sqrt(1 + X * X), sy = std::sqrt(1 + Y * Y);
    const double F =
        (X / sx * std::atan(Y / sx) + Y / sy * std::atan(X / sy)) / (2 * 3.14159265358979);
    return 3.14159265358979 * F;
}

/// A 1 x 1 emitter (Ke 1, facing down, black itself) 1 above the centre of a 10 x 10 floor
/// of albedo 0.5, and a camera that sees the floor's centre at the image centre, past the
/// emitter. No other light.
std::string emitter_scene(const SceneDir& dir) {
    std::ofstream(dir.file("emitter.mtl")) << "newmtl floor\nKd 0.5 0.5 0.5\n"
                                              "newmtl light\nKd 0 0 0\nKe 1 1 1\n";
    std::ofstream(dir.file("emitter.obj"))
        << "mtllib emitter.mtl\n"
           "v -5 0 -5\nv -5 0 5\nv 5 0 5\nv 5 0 -5\n"
           "v -0.5 1 -0.5\nv 0.5 1 -0.5\nv 0.5 1 0.5\nv -0.5 1 0.5\n"
           "usemtl floor\nf 1 2 3\nf 1 3 4\n"
           "usemtl light\nf 5 6 7\nf 5 7 8\n";
    std::ofstream(dir.file("emitter.json"))
        << R"({"camera": {"eye": [0, 0.5, 3], "look": [0, 0, 0], "fov": 20},
               "meshes": [{"file": "emitter.obj"}]})";
    return dir.file("emitter.json");
}

/// The floor's radiance under the emitter's centre: albedo / pi * irradiance, the
/// irradiance of four 0.5 x 0.5 corner rectangles.
double floor_radiance() {
    return 0.5 / 3.14159265358979 * 4 * corner_irradiance(0.5, 0.5, 1.0);
}

TEST(EmissiveTriangles, DirectLightsTheFloorAsTheClosedFormSays) {
    SceneDir dir;
    const RenderResult r = render("direct", emitter_scene(dir), 64, {{"area_samples", "64"}});
    const float3 floor = centre_mean(r, 2);
    EXPECT_NEAR(floor.x, floor_radiance(), 0.03 * floor_radiance()) << "expected " << floor_radiance();
    EXPECT_FLOAT_EQ(floor.x, floor.y);
}

TEST(EmissiveTriangles, ThePathTracersNextEventEstimationAgreesWithTheClosedForm) {
    SceneDir dir;
    const std::string scene = emitter_scene(dir);
    const RenderResult nee = render("pathtracer", scene, 48, {{"spp", "128"}, {"seed", "7"}});
    const float3 floor = centre_mean(nee, 1);
    EXPECT_NEAR(floor.x, floor_radiance(), 0.05 * floor_radiance()) << "expected " << floor_radiance();
    // BSDF sampling alone finds the emitter by chance: the same mean, noisier.
    const RenderResult bsdf =
        render("pathtracer", scene, 48, {{"spp", "1024"}, {"nee", "0"}, {"seed", "8"}});
    const float3 found = centre_mean(bsdf, 1);  // 9,216 paths: about 2 % noise
    EXPECT_NEAR(found.x, floor_radiance(), 0.08 * floor_radiance()) << "expected " << floor_radiance();
}

TEST(EmissiveTriangles, IgiAndRadiosityLightTheFloorFromTheEmitter) {
    SceneDir dir;
    const std::string scene = emitter_scene(dir);
    // IGI's area lights are grids of point emitters and its VPLs are clamped: close, not
    // exact. Radiosity's photons leave the emitter by power.
    const RenderResult igi = render("igi", scene, 48, {{"area_samples", "64"}});
    EXPECT_NEAR(centre_mean(igi, 2).x, floor_radiance(), 0.10 * floor_radiance());
    const RenderResult radiosity = render("radiosity", scene, 48, {});
    EXPECT_GT(centre_mean(radiosity, 2).x, 0.3 * floor_radiance());
}

/// A camera-facing quad with a 2x2 texture, red on the left and blue on the right, lit by
/// a point light in front of it.
std::string textured_quad_scene(const SceneDir& dir) {
    lucent::scene::Image texture;
    texture.width = texture.height = 2;
    texture.pixels = {make_float3(1, 0, 0), make_float3(0, 0, 1), make_float3(1, 0, 0),
                      make_float3(0, 0, 1)};
    lucent::scene::write_image(dir.file("rb.png"), texture);
    std::ofstream(dir.file("quad.mtl")) << "newmtl tex\nKd 1 1 1\nmap_Kd rb.png\n";
    std::ofstream(dir.file("quad.obj")) << "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\n"
                                           "v -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                           "usemtl tex\nf 1/1 2/2 3/3 4/4\n";
    std::ofstream(dir.file("quad.json"))
        << R"({"camera": {"eye": [0, 0, 3], "look": [0, 0, 0], "fov": 50},
               "meshes": [{"file": "quad.obj"}],
               "lights": [{"type": "point", "position": [0, 0, 2], "intensity": [10, 10, 10]}]})";
    return dir.file("quad.json");
}

float3 pixel(const RenderResult& r, float fx, float fy) {
    return r.image.pixels[size_t(fy * r.image.height) * r.image.width + size_t(fx * r.image.width)];
}

TEST(Textures, IgiAndThePathTracerApplyMapKd) {
    SceneDir dir;
    const std::string scene = textured_quad_scene(dir);
    for (const char* sample : {"igi", "pathtracer"}) {
        const RenderResult r = render(sample, scene, 48, {});
        const float3 left = pixel(r, 0.3f, 0.5f), right = pixel(r, 0.7f, 0.5f);
        EXPECT_GT(left.x, 0.0f) << sample;
        EXPECT_GT(left.x, 10 * left.z) << sample << ": left half red";
        EXPECT_GT(right.z, 10 * right.x) << sample << ": right half blue";
    }
}

TEST(SceneFraming, ASceneWithoutACameraGetsOneThatSeesIt) {
    SceneDir dir;
    std::ofstream(dir.file("quad.obj")) << "v 10 10 10\nv 12 10 10\nv 12 12 10\nv 10 12 10\n"
                                           "f 1 2 3 4\n";
    std::ofstream(dir.file("nocam.json"))
        << R"({"meshes": [{"file": "quad.obj"}],
               "lights": [{"type": "point", "position": [11, 11, 14], "intensity": [40, 40, 40]}]})";
    const RenderResult r = render("direct", dir.file("nocam.json"), 32, {});
    // The quad, far from the origin, fills the middle of the frame.
    const float3 middle = pixel(r, 0.5f, 0.5f);
    EXPECT_GT(middle.x + middle.y + middle.z, 0.1f);
}

}  // namespace

namespace {
TEST(Dielectrics, IgiSeesThroughGlass) {
    // cornell-materials: the short block is glass. IGI follows the refracted (and, by
    // Fresnel, reflected) rays to what lies behind and around it, so the block shows the
    // room instead of black.
    const RenderResult r = render("igi", "cornell-materials", 64, {});
    float3 glass = make_float3(0.0f);
    for (float fy = 0.76f; fy < 0.86f; fy += 0.02f)
        for (float fx = 0.56f; fx < 0.70f; fx += 0.02f) glass += pixel(r, fx, fy);
    EXPECT_GT(glass.x + glass.y + glass.z, 0.5f) << "the glass block is black";
}
}  // namespace

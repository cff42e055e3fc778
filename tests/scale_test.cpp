// Scale robustness (issue 26, item 7): the Cornell box scaled by 1e-6 .. 1e6 or moved by
// 1e3 and 1e6, its camera and lights transformed alike, renders the image of the box as
// modelled in every sample that renders a scene; the samples with a built-in scene (Whitted,
// fog) render it alike when their scene is moved so; and a camera that cannot see is refused
// wherever a camera comes from (the scene file, --eye --look --up --fov), with the fix.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "samples/fog/fog_scene.h"
#include "samples/placement.h"
#include "samples/sample.h"
#include "samples/scene_setup.h"
#include "samples/settings_error.h"
#include "samples/whitted/whitted.h"
#include "scene/image_compare.h"
#include "scene/scene.h"
#include "tests/test_support.h"

namespace {

namespace fs = std::filesystem;
using lucent::samples::RenderResult;
using lucent::samples::RenderSettings;
using lucent::samples::Placement;
using lucent::scene::Scene;

std::string name(const Placement& m) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "scale %g offset %g", m.scale, m.offset);
    return buf;
}

/// `s` moved by `m`: vertices, lights and camera alike. A point light's intensity grows with
/// the square of the scale so that its irradiance, I / d^2, stays the same.
Scene placed(Scene s, const Placement& m) {
    for (auto& mesh : s.meshes)
        for (auto& p : mesh.positions) p = m.point(p);
    for (auto& l : s.area_lights) {
        l.corner = m.point(l.corner);
        l.edge1 = m.vector(l.edge1);
        l.edge2 = m.vector(l.edge2);
    }
    for (auto& l : s.point_lights) {
        l.position = m.point(l.position);
        l.intensity = m.intensity(l.intensity);
    }
    s.camera = m.camera(s.camera);
    return s;
}

std::string json_vector(float3 v) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "[%.9g, %.9g, %.9g]", double(v.x), double(v.y), double(v.z));
    return buf;
}

/// The scene as a JSON scene description (docs/scenes.md): how a user hands the samples a
/// scene of their own; floats written with 9 digits, so they read back exactly.
std::string scene_json(const Scene& s) {
    std::ostringstream json;
    json << "{\"camera\": {\"eye\": " << json_vector(s.camera.eye)
         << ", \"look\": " << json_vector(s.camera.look) << ", \"up\": " << json_vector(s.camera.up)
         << ", \"fov\": " << s.camera.fov_degrees << "},\n\"materials\": [";
    for (size_t i = 0; i < s.materials.size(); ++i) {
        const auto& m = s.materials[i];
        json << (i ? ",\n" : "") << "{\"name\": \"" << m.name
             << "\", \"diffuse\": " << json_vector(m.diffuse)
             << ", \"emission\": " << json_vector(m.emission) << "}";
    }
    json << "],\n\"meshes\": [";
    for (size_t i = 0; i < s.meshes.size(); ++i) {
        const auto& mesh = s.meshes[i];
        json << (i ? ",\n" : "") << "{\"material\": \"" << s.materials[mesh.materials[0]].name
             << "\", \"positions\": [";
        for (size_t v = 0; v < mesh.positions.size(); ++v)
            json << (v ? ", " : "") << json_vector(mesh.positions[v]);
        json << "], \"triangles\": [";
        for (size_t t = 0; t < mesh.indices.size(); ++t)
            json << (t ? ", " : "") << "[" << mesh.indices[t].x << ", " << mesh.indices[t].y
                 << ", " << mesh.indices[t].z << "]";
        json << "]}";
    }
    json << "],\n\"lights\": [";
    const char* sep = "";
    for (const auto& l : s.area_lights) {
        json << sep << "{\"type\": \"area\", \"corner\": " << json_vector(l.corner)
             << ", \"edge1\": " << json_vector(l.edge1) << ", \"edge2\": " << json_vector(l.edge2)
             << ", \"emission\": " << json_vector(l.emission) << "}";
        sep = ",\n";
    }
    for (const auto& l : s.point_lights) {
        json << sep << "{\"type\": \"point\", \"position\": " << json_vector(l.position)
             << ", \"intensity\": " << json_vector(l.intensity) << "}";
        sep = ",\n";
    }
    json << "]}\n";
    return json.str();
}

/// The Cornell box's meshes each take one material per mesh in JSON: split the room's walls
/// by material so every JSON mesh has one.
Scene one_material_per_mesh(const Scene& s) {
    Scene out = s;
    out.meshes.clear();
    for (const auto& mesh : s.meshes)
        for (unsigned material = 0; material < s.materials.size(); ++material) {
            lucent::scene::Mesh part;
            part.name = mesh.name + "-" + s.materials[material].name;
            for (size_t t = 0; t < mesh.indices.size(); ++t) {
                if (mesh.materials[t] != material) continue;
                const unsigned base = unsigned(part.positions.size());
                part.positions.push_back(mesh.positions[mesh.indices[t].x]);
                part.positions.push_back(mesh.positions[mesh.indices[t].y]);
                part.positions.push_back(mesh.positions[mesh.indices[t].z]);
                part.indices.push_back(uint3{base, base + 1, base + 2});
                part.materials.push_back(material);
            }
            if (!part.indices.empty()) out.meshes.push_back(std::move(part));
        }
    return out;
}

class ScaledScene : public ::testing::Test {
  protected:
    void SetUp() override {
        dir = fs::temp_directory_path() /
              ("lucent_scale_test_" + std::to_string(::getpid()) + "_" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(dir);
    }
    void TearDown() override { fs::remove_all(dir); }

    /// The file of `base` placed by `m`.
    std::string write(const Scene& base, const Placement& m, const std::string& stem) {
        const fs::path path = dir / (stem + ".json");
        std::ofstream(path) << scene_json(placed(base, m));
        return path.string();
    }

    fs::path dir;
};

RenderResult render(const std::string& sample, const std::string& scene,
                    const std::map<std::string, std::string>& sets, unsigned spp) {
    RenderSettings settings;
    settings.width = settings.height = 48;
    settings.backend = lucent_tests::test_backend();
    settings.threads = 2;
    settings.scene = scene;
    settings.sets = sets;
    settings.spp = spp;
    return lucent::samples::find_sample(sample).render(settings);
}

/// Scaled about 0, every float keeps its relative spacing, so the images agree to rounding:
/// measured below 4e-11 in every sample (before: up to 0.29, the path tracer at 1e-6).
constexpr double kMaxRelmseScaled = 1e-6;
/// Moved by 1e3 the spacing grows 8x (1/4096 mm): measured at most 3.6e-6 (radiosity).
constexpr double kMaxRelmseNear = 1e-4;

/// Each sample that renders a scene, with settings small enough for a test, and the most
/// relative MSE (lucent::scene::compare_images) its render of the box moved to 1e6 may be
/// from the box at 0. The random streams are keyed by pixel and frame, not by position, so
/// a sample renders the moved box with the same random numbers: what differs is rounding.
/// At 1e6 a float's spacing is 1/16 mm, a nine-thousandth of the box, and the light hangs
/// 1.6 spacings below the ceiling: rays cross edges here and there, and a path that does
/// carries its difference through its bounces. Measured (48x48, CPU): direct 5.4e-4,
/// pathtracer 0.0127, igi 0.0047, radiosity 0.0049; before the offset of Wächter and Binder
/// 0.025, 0.29, 0.055 and 0.099. The bounds are about twice the measured figures.
struct SampleCase {
    std::string sample;
    std::map<std::string, std::string> sets;
    unsigned spp;
    double max_relmse_scaled;  // scaled about 0
    double max_relmse_far;     // moved by 1e6
};

const std::vector<SampleCase>& sample_cases() {
    static const std::vector<SampleCase> cases = {
        {"direct", {{"area_samples", "4"}}, 0, kMaxRelmseScaled, 0.002},
        // The GPU's megakernel contracts products into FMAs, so a scaled scene's rounding
        // differs a little from the original's and a few of the path tracer's 2-spp paths
        // take another bounce: on the H200 0.0054 at scales 1e-3 and 1e6 (the CPU: 7e-12).
        // Still far below the 0.29 of the absolute epsilon this test was written against.
        {"pathtracer", {{"max_depth", "4"}}, 2, 0.02, 0.03},
        {"igi", {{"vpls", "32"}, {"area_samples", "1"}}, 0, kMaxRelmseScaled, 0.01},
        {"radiosity", {{"photons", "64"}, {"area_samples", "4"}}, 0, kMaxRelmseScaled, 0.01},
    };
    return cases;
}

double max_relmse(const SampleCase& c, const Placement& m) {
    if (m.offset == 0) return c.max_relmse_scaled;
    return m.offset <= 1e3 ? kMaxRelmseNear : c.max_relmse_far;
}

/// Whitted's spheres (a 40 x 40 floor) moved to 1e6, where floats are 1/16 apart: the glass
/// shell, 0.04 thick, is thinner than that and cannot be modelled there, so the pixels that
/// may see it are left out (without_glass); in the rest the camera, rounded to 1/16, moves
/// the checker's edges by a pixel here and there. Measured 0.133 (48x48, CPU); the fixed
/// epsilon of 1e-3 measured 0.113 here too (edges dominate), but its rays hit the surfaces
/// they left: the lit side of the metal sphere is checked pixel by pixel below.
constexpr double kWhittedMaxRelmseFar = 0.25;
/// The fog's scene (a 24 x 24 floor) moved to 1e6: the crystal's and the box's edges and
/// the floor's grout lines move with the rounding. The fog itself is noise drawn from the
/// same TEA key (seed 0) at the same points relative to the scene, so it is no source of
/// difference: there is no random sampling in the fog sample. Measured 0.0070 (48x36, CPU);
/// the fixed epsilon of 1e-3 with the noise at absolute coordinates 0.0143.
constexpr double kFogMaxRelmseFar = 0.012;

const std::vector<Placement>& placements() {
    static const std::vector<Placement> all = {
        {1e-6, 0}, {1e-3, 0}, {1e3, 0}, {1e6, 0}, {1, 1e3}, {1, 1e6},
    };
    return all;
}

TEST_F(ScaledScene, EverySampleRendersTheCornellBoxAlikeAtEveryScaleAndOffset) {
    const Scene box = one_material_per_mesh(lucent::scene::cornell_box(true));
    const std::string reference_scene = write(box, Placement{}, "reference");
    for (const SampleCase& c : sample_cases()) {
        const RenderResult reference = render(c.sample, reference_scene, c.sets, c.spp);
        double brightness = 0;
        for (const float3& p : reference.image.pixels) brightness += p.x + p.y + p.z;
        ASSERT_GT(brightness / reference.image.pixels.size(), 0.05)
            << c.sample << ": the reference is lit";
        for (const Placement& m : placements()) {
            const std::string scene = write(box, m, "placed");
            const RenderResult r = render(c.sample, scene, c.sets, c.spp);
            EXPECT_EQ(r.report.exception_count(), 0u) << c.sample << ", " << name(m);
            const auto diff = lucent::scene::compare_images(reference.image, r.image);
            std::printf("%-10s %-22s relmse %.3g rmse %.3g flip %.3g\n", c.sample.c_str(),
                        name(m).c_str(), diff.relmse, diff.rmse, diff.flip_mean);
            EXPECT_LT(diff.relmse, max_relmse(c, m)) << c.sample << ", " << name(m);
        }
    }
}

// ---- the samples' own scenes ---------------------------------------------------------------

/// The most relative MSE a built-in scene's render, moved by `m`, may be from its render as
/// modelled: `far` at offset 1e6, the bounds above elsewhere.
double max_relmse_built_in(const Placement& m, double far) {
    if (m.offset == 0) return kMaxRelmseScaled;
    return m.offset <= 1e3 ? kMaxRelmseNear : far;
}

/// `image` with the pixels that may see Whitted's glass sphere (in a size x size render, its
/// projected disc and a margin) taken from `from`: what is left is the floor, the metal
/// sphere and their shadows.
lucent::scene::Image without_glass(lucent::scene::Image image, const lucent::scene::Image& from) {
    using lucent::samples::whitted_layout;
    using lucent::samples::whitted_project;
    const auto& l = whitted_layout();
    const float2 centre = whitted_project(l.glass_center, image.width, image.height);
    // The farthest projection of the sphere's three great circles, widened for perspective.
    float radius = 0;
    for (int i = 0; i < 64; ++i) {
        const float a = float(i) * 0.0981748f, c = std::cos(a) * l.glass_radius,
                    s = std::sin(a) * l.glass_radius;
        for (const float3 p : {make_float3(c, s, 0), make_float3(0, c, s), make_float3(c, 0, s)}) {
            const float2 q = whitted_project(l.glass_center + p, image.width, image.height);
            radius = std::max(radius, std::hypot(q.x - centre.x, q.y - centre.y));
        }
    }
    radius = 1.15f * radius + 1.5f;
    for (unsigned y = 0; y < image.height; ++y)
        for (unsigned x = 0; x < image.width; ++x)
            if (std::hypot(x + 0.5f - centre.x, y + 0.5f - centre.y) < radius)
                image.pixels[size_t(y) * image.width + x] = from.pixels[size_t(y) * image.width + x];
    return image;
}

/// The mean of the 3 x 3 pixels about image position `p`.
float3 patch_mean(const lucent::scene::Image& image, float2 p) {
    float3 sum = make_float3(0.0f);
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
            sum += image.pixels[size_t(int(p.y) + dy) * image.width + size_t(int(p.x) + dx)];
    return sum * (1.0f / 9.0f);
}

TEST(ScaledBuiltInScene, WhittedRendersItsSpheresAlikeAtEveryScaleAndOffset) {
    RenderSettings settings;
    settings.width = settings.height = 48;
    settings.backend = lucent_tests::test_backend();
    settings.threads = 2;
    settings.sets = {{"lights", "3"}};  // the fill lights are placed too
    const RenderResult reference = lucent::samples::render_whitted(settings, Placement{});
    // Where shadow rays and reflections show: the metal sphere's side that faces the key
    // light (self-shadowed where a ray hits the surface it leaves) and the centre of its
    // shadow on the floor (lost where the shadow ray starts above the sphere: a shadowed
    // pixel is a third as bright as a lit one). Placed alike, the image positions are the
    // modelled scene's. Within 15 %: at 1e6 a patch's checker edges move (measured 8 %).
    const auto& l = lucent::samples::whitted_layout();
    const float3 lit_side =
        l.metal_center + normalize(l.key_light - l.metal_center) * l.metal_radius;
    const float s = (l.floor_height - l.key_light.y) / (l.metal_center.y - l.key_light.y);
    const float3 shadow = l.key_light + (l.metal_center - l.key_light) * s;
    for (const Placement& m : placements()) {
        const RenderResult r = lucent::samples::render_whitted(settings, m);
        EXPECT_EQ(r.report.exception_count(), 0u) << name(m);
        const auto diff = lucent::scene::compare_images(reference.image, r.image);
        const auto outside = lucent::scene::compare_images(
            reference.image, without_glass(r.image, reference.image));
        std::printf("%-10s %-22s relmse %.3g rmse %.3g flip %.3g; without the glass %.3g\n",
                    "whitted", name(m).c_str(), diff.relmse, diff.rmse, diff.flip_mean,
                    outside.relmse);
        if (m.offset < 1e6)
            EXPECT_LT(diff.relmse, max_relmse_built_in(m, 0)) << name(m);
        else
            EXPECT_LT(outside.relmse, kWhittedMaxRelmseFar) << name(m);
        for (const float3 p : {lit_side, shadow}) {
            const float2 at = lucent::samples::whitted_project(p, 48, 48);
            const float expected = max_component(patch_mean(reference.image, at));
            EXPECT_NEAR(max_component(patch_mean(r.image, at)), expected, 0.15f * expected)
                << name(m) << ", the pixels about (" << at.x << ", " << at.y << ")";
        }
    }
}

/// One frame of the fog sample's scene moved by `m`, with the sample's default options.
RenderResult render_fog(const Placement& m) {
    const lucent::samples::FogOptions options;  // TEA noise of seed 0, linear falloff
    RenderSettings settings;
    settings.backend = lucent_tests::test_backend();
    settings.threads = 2;
    lucent::samples::FogScene scene(options, 48, 36, settings.context_options(), m);
    RenderResult out;
    out.report = scene.render(options.orbit_degrees);
    out.image = lucent::samples::image_from_output(scene.output());
    return out;
}

TEST(ScaledBuiltInScene, FogRendersItsFogAlikeAtEveryScaleAndOffset) {
    const RenderResult reference = render_fog(Placement{});
    for (const Placement& m : placements()) {
        const RenderResult r = render_fog(m);
        EXPECT_EQ(r.report.exception_count(), 0u) << name(m);
        const auto diff = lucent::scene::compare_images(reference.image, r.image);
        std::printf("%-10s %-22s relmse %.3g rmse %.3g flip %.3g\n", "fog", name(m).c_str(),
                    diff.relmse, diff.rmse, diff.flip_mean);
        EXPECT_LT(diff.relmse, max_relmse_built_in(m, kFogMaxRelmseFar)) << name(m);
    }
}

// ---- cameras that cannot see -----------------------------------------------------------------

/// The Cornell box with `camera` as its JSON camera.
std::string with_camera(const fs::path& dir, const lucent::scene::Camera& camera) {
    Scene box = one_material_per_mesh(lucent::scene::cornell_box(true));
    box.camera = camera;
    const fs::path path = dir / "camera.json";
    std::ofstream(path) << scene_json(box);
    return path.string();
}

TEST_F(ScaledScene, AJsonCameraThatCannotSeeIsRefusedWithItsKey) {
    using lucent::scene::Camera;
    const float3 eye{278, 273, -800}, look{278, 273, 0};
    struct Bad {
        Camera camera;
        std::string key;
    };
    for (const Bad& bad : {Bad{Camera{eye, look, {0, 0, 1}, 40}, "/camera/up"},
                           Bad{Camera{eye, look, {0, 0, -3}, 40}, "/camera/up"},
                           Bad{Camera{eye, look, {0, 0, 0}, 40}, "/camera/up"},
                           Bad{Camera{eye, eye, {0, 1, 0}, 40}, "same point"},
                           Bad{Camera{eye, look, {0, 1, 0}, 180}, "/camera/fov"},
                           Bad{Camera{eye, look, {0, 1, 0}, 0}, "/camera/fov"}}) {
        const std::string path = with_camera(dir, bad.camera);
        lucent_tests::expect_error([&] { lucent::scene::load_scene(path); },
                                   {"camera.json", bad.key}, bad.key.c_str());
    }
    // An up at an angle to the view loads: only the degenerate ones are refused.
    EXPECT_NO_THROW(lucent::scene::load_scene(with_camera(dir, Camera{eye, look, {0, 1, 1}, 40})));
}

TEST_F(ScaledScene, EveryDegenerateCameraFlagIsRefusedByEverySampleBeforeItRenders) {
    struct Bad {
        lucent::samples::CameraOverride camera;
        std::vector<std::string> words;
    };
    const float3 eye{278, 273, -800};
    std::vector<Bad> bads;
    bads.push_back({{eye, float3{278, 1000, -800}, std::nullopt, std::nullopt},
                    {"up", "along the view direction", "--up"}});  // looking straight up, up +y
    bads.push_back({{eye, eye, std::nullopt, std::nullopt}, {"same point", "--eye", "--look"}});
    bads.push_back({{std::nullopt, std::nullopt, float3{0, 0, 0}, std::nullopt}, {"up 0,0,0", "--up"}});
    bads.push_back({{std::nullopt, std::nullopt, std::nullopt, 180.0f}, {"fov 180", "--fov"}});
    bads.push_back({{std::nullopt, std::nullopt, std::nullopt, -5.0f}, {"fov -5", "(0, 180)"}});
    for (const lucent::samples::Sample* sample : lucent::samples::all_samples()) {
        if (sample->name == "tea") continue;  // noise images: no camera
        for (const Bad& bad : bads) {
            RenderSettings settings;
            settings.width = settings.height = 8;
            settings.backend = lucent_tests::test_backend();
            settings.threads = 2;
            settings.camera = bad.camera;
            try {
                sample->render(settings);
                ADD_FAILURE() << sample->name << ": rendered with " << bad.words[0];
            } catch (const lucent::samples::SettingsError& e) {
                for (const std::string& word : bad.words)
                    EXPECT_NE(std::string(e.what()).find(word), std::string::npos)
                        << sample->name << ": " << e.what() << " should name " << word;
            }
        }
    }
}

}  // namespace

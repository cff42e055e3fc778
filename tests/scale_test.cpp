// Scale robustness (issue 26, item 7): the Cornell box scaled by 1e-6 .. 1e6 or moved by
// 1e3 and 1e6, its camera and lights transformed alike, renders the image of the box as
// modelled in every sample that renders a scene; and a camera that cannot see is refused
// wherever a camera comes from (the scene file, --eye --look --up --fov), with the fix.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "samples/sample.h"
#include "samples/settings_error.h"
#include "scene/image_compare.h"
#include "scene/scene.h"
#include "tests/test_support.h"

namespace {

namespace fs = std::filesystem;
using lucent::samples::RenderResult;
using lucent::samples::RenderSettings;
using lucent::scene::Scene;

/// A similarity transform p -> scale * p + offset (the offset on all three axes), computed
/// in double and rounded once, as a modelling tool would write the moved scene.
struct Placement {
    double scale = 1, offset = 0;
    float3 point(float3 p) const {
        return make_float3(float(scale * p.x + offset), float(scale * p.y + offset),
                           float(scale * p.z + offset));
    }
    float3 vector(float3 v) const {
        return make_float3(float(scale * v.x), float(scale * v.y), float(scale * v.z));
    }
    std::string name() const {
        char buf[64];
        std::snprintf(buf, sizeof buf, "scale %g offset %g", scale, offset);
        return buf;
    }
};

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
        l.intensity = l.intensity * float(m.scale * m.scale);
    }
    s.camera.eye = m.point(s.camera.eye);
    s.camera.look = m.point(s.camera.look);
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
            EXPECT_EQ(r.report.exception_count(), 0u) << c.sample << ", " << m.name();
            const auto diff = lucent::scene::compare_images(reference.image, r.image);
            std::printf("%-10s %-22s relmse %.3g rmse %.3g flip %.3g\n", c.sample.c_str(),
                        m.name().c_str(), diff.relmse, diff.rmse, diff.flip_mean);
            EXPECT_LT(diff.relmse, max_relmse(c, m)) << c.sample << ", " << m.name();
        }
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

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
    void TearDown() override { if (!getenv("DUMP")) fs::remove_all(dir); }

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

/// Each sample that renders a scene, with settings small enough for a test, and the most
/// relative MSE (lucent::scene::compare_images) its scaled renders may be from the box at
/// scale 1. The random streams are keyed by pixel and frame, not by position, so a sample
/// renders the moved box with the same random numbers: what differs is rounding, which
/// moves a ray across an edge here and there (a light's edge, a block's silhouette).
struct SampleCase {
    std::string sample;
    std::map<std::string, std::string> sets;
    unsigned spp;
    double max_relmse;
};

const std::vector<SampleCase>& sample_cases() {
    static const std::vector<SampleCase> cases = {
        {"direct", {{"area_samples", "4"}}, 0, 0.01},
        {"pathtracer", {{"max_depth", "4"}}, 2, 0.05},
        {"igi", {{"vpls", "32"}, {"area_samples", "1"}}, 0, 0.05},
        {"radiosity", {{"photons", "64"}, {"area_samples", "4"}}, 0, 0.05},
    };
    return cases;
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
            const std::string scene = write(box, m, "placed" + std::to_string(m.scale) + "_" + std::to_string(m.offset));
            const RenderResult r = render(c.sample, scene, c.sets, c.spp);
            EXPECT_EQ(r.report.exception_count(), 0u) << c.sample << ", " << m.name();
            const auto diff = lucent::scene::compare_images(reference.image, r.image);
            std::printf("%-10s %-22s relmse %.3g rmse %.3g flip %.3g\n", c.sample.c_str(),
                        m.name().c_str(), diff.relmse, diff.rmse, diff.flip_mean);
            EXPECT_LT(diff.relmse, c.max_relmse) << c.sample << ", " << m.name();
            if (getenv("DUMP")) { lucent::scene::write_image("/tmp/scale_dump/" + c.sample + "_" + std::to_string(m.scale) + "_" + std::to_string(m.offset) + ".pfm", r.image); lucent::scene::write_image("/tmp/scale_dump/" + c.sample + "_ref.pfm", reference.image);}
        }
    }
}

}  // namespace

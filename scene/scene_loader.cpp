// load_scene: a built-in scene by name, or a file by its extension.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "lucent/error.h"
#include "scene/scene.h"

namespace lucent::scene {

size_t Scene::triangle_count() const {
    size_t n = 0;
    for (const Mesh& m : meshes) n += m.indices.size();
    return n;
}

size_t Scene::drawn_triangle_count() const {
    if (instances.empty()) return triangle_count();
    size_t n = 0;
    for (const Instance& i : instances) n += meshes.at(i.mesh).indices.size();
    return n;
}

Matrix4x3 identity_matrix() { return Matrix4x3{{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}}; }

Matrix4x3 multiply(const Matrix4x3& a, const Matrix4x3& b) {
    Matrix4x3 r{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j) {
            float v = j == 3 ? a.m[i * 4 + 3] : 0.0f;  // b's implied last row is 0 0 0 1
            for (int k = 0; k < 3; ++k) v += a.m[i * 4 + k] * b.m[k * 4 + j];
            r.m[i * 4 + j] = v;
        }
    return r;
}

bool invert(const Matrix4x3& m, Matrix4x3& out) {
    // The 3x3 part by its adjugate, in double: instance scales span orders of magnitude.
    const double a = m.m[0], b = m.m[1], c = m.m[2], d = m.m[4], e = m.m[5], f = m.m[6],
                 g = m.m[8], h = m.m[9], k = m.m[10];
    const double A = e * k - f * h, B = f * g - d * k, C = d * h - e * g;
    const double det = a * A + b * B + c * C;
    if (!(std::fabs(det) > 1e-30) || !std::isfinite(det)) return false;
    const double inv[9] = {A / det, (c * h - b * k) / det, (b * f - c * e) / det,
                           B / det, (a * k - c * g) / det, (c * d - a * f) / det,
                           C / det, (b * g - a * h) / det, (a * e - b * d) / det};
    const double t[3] = {m.m[3], m.m[7], m.m[11]};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) out.m[i * 4 + j] = float(inv[i * 3 + j]);
        out.m[i * 4 + 3] =
            float(-(inv[i * 3] * t[0] + inv[i * 3 + 1] * t[1] + inv[i * 3 + 2] * t[2]));
    }
    return true;
}

std::vector<Instance> drawn_instances(const Scene& scene) {
    if (!scene.instances.empty()) return scene.instances;
    std::vector<Instance> all;
    for (unsigned i = 0; i < scene.meshes.size(); ++i) all.push_back({i, identity_matrix()});
    return all;
}

unsigned add_untransformed_mesh(Scene& scene, Mesh mesh) {
    const unsigned index = unsigned(scene.meshes.size());
    scene.meshes.push_back(std::move(mesh));
    if (!scene.instances.empty()) scene.instances.push_back({index, identity_matrix()});
    return index;
}

std::vector<std::string> builtin_scene_names() {
    return {"cornell", "cornell-point", "cornell-materials"};
}

namespace {
/// A scene around one mesh: a grey material, a camera on +z framing its bounds, and a point
/// light at the camera (a JSON file that names the mesh gives any other setup).
Scene single_mesh_scene(Mesh mesh) {
    Scene scene;
    scene.name = std::filesystem::path(mesh.name).stem().string();
    scene.materials.push_back(Material{"default", {0.8f, 0.8f, 0.8f}, {0, 0, 0}, 0, {0, 0, 0}, ""});
    scene.meshes.push_back(std::move(mesh));
    scene.camera = framing_camera(scene);
    const float radius = length(scene.camera.eye - scene.camera.look) / 2.8f;
    const float power = 4.0f * radius * radius;  // a few times the mesh's own scale
    scene.point_lights.push_back(
        {scene.camera.eye + make_float3(0, radius, 0), make_float3(power)});
    return scene;
}
}  // namespace

Scene load_scene(const std::string& name_or_path, const LoadProgress& progress) {
    if (name_or_path == "cornell") return cornell_box(/*area_light=*/true);
    if (name_or_path == "cornell-point") return cornell_box(/*area_light=*/false);
    if (name_or_path == "cornell-materials") return cornell_materials_box();
    std::string ext = std::filesystem::path(name_or_path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".obj") return load_obj_scene(name_or_path, progress);
    if (ext == ".json") return load_json_scene(name_or_path, progress);
    if (ext == ".ply") return single_mesh_scene(load_ply_mesh(name_or_path, progress));
    if (ext == ".gltf" || ext == ".glb") return load_gltf_scene(name_or_path);
    std::string names;
    for (const std::string& n : builtin_scene_names()) names += (names.empty() ? "" : ", ") + n;
    throw Error("scene '" + name_or_path + "': not a built-in scene (" + names +
                ") nor a .obj, .ply, .json, .gltf or .glb file");
}

}  // namespace lucent::scene

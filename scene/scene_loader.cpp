// load_scene: a built-in scene by name, or a file by its extension.
#include <algorithm>
#include <filesystem>

#include "lucent/error.h"
#include "scene/scene.h"

namespace lucent::scene {

size_t Scene::triangle_count() const {
    size_t n = 0;
    for (const Mesh& m : meshes) n += m.indices.size();
    return n;
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

Scene load_scene(const std::string& name_or_path) {
    if (name_or_path == "cornell") return cornell_box(/*area_light=*/true);
    if (name_or_path == "cornell-point") return cornell_box(/*area_light=*/false);
    if (name_or_path == "cornell-materials") return cornell_materials_box();
    std::string ext = std::filesystem::path(name_or_path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".obj") return load_obj_scene(name_or_path);
    if (ext == ".json") return load_json_scene(name_or_path);
    if (ext == ".ply") return single_mesh_scene(load_ply_mesh(name_or_path));
    std::string names;
    for (const std::string& n : builtin_scene_names()) names += (names.empty() ? "" : ", ") + n;
    throw Error("scene '" + name_or_path + "': not a built-in scene (" + names +
                ") nor a .obj, .ply or .json file");
}

}  // namespace lucent::scene

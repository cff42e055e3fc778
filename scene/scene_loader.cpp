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
    return {"cornell", "cornell-point"};
}

Scene load_scene(const std::string& name_or_path) {
    if (name_or_path == "cornell") return cornell_box(/*area_light=*/true);
    if (name_or_path == "cornell-point") return cornell_box(/*area_light=*/false);
    std::string ext = std::filesystem::path(name_or_path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".obj") return load_obj_scene(name_or_path);
    if (ext == ".json") return load_json_scene(name_or_path);
    std::string names;
    for (const std::string& n : builtin_scene_names()) names += (names.empty() ? "" : ", ") + n;
    throw Error("scene '" + name_or_path + "': not a built-in scene (" + names +
                ") nor a .obj or .json file");
}

}  // namespace lucent::scene

// A Scene from a JSON description (nlohmann-json): camera, materials, meshes (OBJ files or
// inline triangles), instances placing meshes by transforms, and point or area lights. Syntax errors name file:line:column; other
// errors name the file and the JSON location ("/lights/1/position") and what is expected.
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <vector>
#include <sstream>

#include "lucent/error.h"
#include "scene/input_file.h"
#include "scene/scene.h"

namespace lucent::scene {

namespace {
namespace fs = std::filesystem;
using nlohmann::json;

class JsonReader {
  public:
    explicit JsonReader(std::string path) : m_path(std::move(path)) {}

    [[noreturn]] void fail(const std::string& where, const std::string& message) const {
        throw Error(m_path + ": " + where + ": " + message);
    }

    float number(const json& j, const std::string& where) const {
        if (!j.is_number()) fail(where, "expected a number, got " + std::string(j.type_name()));
        float v = j.get<float>();
        if (!std::isfinite(v)) fail(where, "the number is not finite");
        return v;
    }

    float3 vec3(const json& j, const std::string& where) const {
        if (!j.is_array() || j.size() != 3)
            fail(where, "expected an array of 3 numbers, like [0, 1, 0]");
        return make_float3(number(j[0], where + "/0"), number(j[1], where + "/1"),
                           number(j[2], where + "/2"));
    }

    const json& member(const json& object, const char* key, const std::string& where) const {
        if (!object.is_object()) fail(where, "expected an object");
        auto it = object.find(key);
        if (it == object.end()) fail(where, std::string("missing \"") + key + "\"");
        return *it;
    }

    /// Every key of `object` must be one of `known`: a typo is an error, not ignored.
    void only(const json& object, std::initializer_list<const char*> known,
              const std::string& where) const {
        for (auto it = object.begin(); it != object.end(); ++it) {
            bool ok = false;
            for (const char* k : known) ok = ok || it.key() == k;
            if (!ok) {
                std::string list;
                for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
                fail(where + "/" + it.key(), "unknown key; expected one of: " + list);
            }
        }
    }

    /// A file named by the scene: relative to the JSON file, else (for a relative name not
    /// found there) in the directories of $LUCENT_SCENE_PATH, ':'-separated, so that a scene
    /// description can name a large model kept elsewhere (e.g. ../shared/scenes).
    fs::path resolve(const std::string& file) const {
        const fs::path beside = fs::path(m_path).parent_path() / file;
        std::error_code ec;
        if (fs::path(file).is_absolute() || fs::exists(beside, ec)) return beside;
        if (const char* search = std::getenv("LUCENT_SCENE_PATH")) {
            std::string dirs = search;
            for (size_t start = 0; start <= dirs.size();) {
                const size_t end = std::min(dirs.find(':', start), dirs.size());
                const fs::path candidate = fs::path(dirs.substr(start, end - start)) / file;
                if (end > start && fs::exists(candidate, ec)) return candidate;
                start = end + 1;
            }
        }
        return beside;
    }

  private:
    std::string m_path;
};

/// JSON allows a key twice in one object and nlohmann-json keeps the last value, so a scene
/// written so loses the first without a word; it is refused instead, by its location. The
/// parser's callback follows the objects and arrays being read to name it.
class DuplicateKeyCheck {
  public:
    explicit DuplicateKeyCheck(std::string path) : m_path(std::move(path)) {}

    bool operator()(int, json::parse_event_t event, json& parsed) {
        switch (event) {
            case json::parse_event_t::object_start:
                m_stack.push_back(Frame{true});
                break;
            case json::parse_event_t::array_start:
                m_stack.push_back(Frame{false});
                break;
            case json::parse_event_t::key: {
                Frame& f = m_stack.back();
                f.key = parsed.get<std::string>();
                if (!f.keys.insert(f.key).second)
                    throw Error(m_path + ": " + pointer() + ": the key '" + f.key +
                                "' appears twice in one object; keep one (JSON keeps only the "
                                "last, the first would be lost)");
                break;
            }
            case json::parse_event_t::object_end:
            case json::parse_event_t::array_end:
                m_stack.pop_back();
                [[fallthrough]];
            case json::parse_event_t::value:
                if (!m_stack.empty() && !m_stack.back().object) ++m_stack.back().index;
                break;
        }
        return true;
    }

  private:
    struct Frame {
        bool object;
        std::set<std::string> keys{};
        std::string key{};
        size_t index = 0;
    };
    /// The JSON pointer of the innermost key being read.
    std::string pointer() const {
        std::string out;
        for (const Frame& f : m_stack) out += "/" + (f.object ? f.key : std::to_string(f.index));
        return out;
    }
    std::string m_path;
    std::vector<Frame> m_stack;
};

json parse_file(const std::string& path) {
    require_regular_file(path, "scene file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open the scene file (check the path)");
    // Read in 1 MiB blocks, each checked for a NUL byte: nlohmann-json ends its input at
    // one, so a scene followed by binary data was accepted without it, and a sparse file
    // was read whole (a 1 GB one took 2 GB) before failing at its first byte.
    std::string text;
    text.reserve(size_t(file_size(path)));
    std::vector<char> block(size_t(1) << 20);
    while (in.read(block.data(), std::streamsize(block.size())) || in.gcount() > 0) {
        const size_t n = size_t(in.gcount());
        if (const void* nul = std::memchr(block.data(), '\0', n)) {
            text.append(block.data(), size_t(static_cast<const char*>(nul) - block.data()));
            size_t line = 1, column = 1;
            for (char c : text) c == '\n' ? (++line, column = 1) : ++column;
            throw Error(path + ":" + std::to_string(line) + ":" + std::to_string(column) +
                        ": a NUL byte: a scene file is JSON text (this one is damaged, sparse "
                        "or not JSON)");
        }
        text.append(block.data(), n);
    }
    try {
        return json::parse(text, DuplicateKeyCheck(path));
    } catch (const json::parse_error& e) {
        size_t line = 1, column = 1;
        for (size_t i = 0; i + 1 < e.byte && i < text.size(); ++i, ++column)
            if (text[i] == '\n') ++line, column = 0;
        std::string what = e.what();
        const size_t colon = what.find("syntax error");
        throw Error(path + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " +
                    (colon == std::string::npos ? what : what.substr(colon)));
    } catch (const json::exception& e) {  // e.g. a number too large for a double
        throw Error(path + ": " + e.what());
    }
}

/// A 3x3 rotation of `degrees` about `axis` (Rodrigues), as the rows of a Matrix4x3.
Matrix4x3 rotation(float3 axis, float degrees) {
    const float3 a = normalize(axis);
    const float r = degrees * 3.14159265358979f / 180.0f, c = std::cos(r), s = std::sin(r),
                t = 1 - c;
    return Matrix4x3{{t * a.x * a.x + c, t * a.x * a.y - s * a.z, t * a.x * a.z + s * a.y, 0,
                      t * a.x * a.y + s * a.z, t * a.y * a.y + c, t * a.y * a.z - s * a.x, 0,
                      t * a.x * a.z - s * a.y, t * a.y * a.z + s * a.x, t * a.z * a.z + c, 0}};
}

/// "instances": [{"mesh": i, "translate": [x,y,z], "rotate": [ax,ay,az,degrees],
/// "scale": s or [sx,sy,sz]}] (applied scale, then rotate, then translate), or "matrix": 12
/// numbers, the rows of a 3x4 object-to-world matrix. Each places every Scene mesh that
/// /meshes/i gave; with instances, a mesh no instance places is an error (it would vanish).
void read_instances(const JsonReader& r, const json& list,
                    const std::vector<std::pair<unsigned, unsigned>>& mesh_range, Scene& scene) {
    if (!list.is_array() || list.empty())
        r.fail("/instances", "expected an array of instances: [{\"mesh\": 0, \"translate\": [x,y,z]}]");
    std::vector<bool> placed(mesh_range.size(), false);
    for (size_t i = 0; i < list.size(); ++i) {
        const std::string at = "/instances/" + std::to_string(i);
        const json& inst = list[i];
        r.only(inst, {"mesh", "translate", "rotate", "scale", "matrix"}, at);
        const json& mesh = r.member(inst, "mesh", at);
        if (!mesh.is_number_integer() || mesh.get<long long>() < 0 ||
            mesh.get<long long>() >= (long long)mesh_range.size())
            r.fail(at + "/mesh", "expected the index of an entry of /meshes, 0.." +
                                     std::to_string(mesh_range.size()) + " (exclusive)");
        const size_t m = mesh.get<size_t>();
        Matrix4x3 transform = identity_matrix();
        if (inst.contains("matrix")) {
            if (inst.contains("translate") || inst.contains("rotate") || inst.contains("scale"))
                r.fail(at + "/matrix", "give either \"matrix\" or translate/rotate/scale");
            const json& mat = inst["matrix"];
            if (!mat.is_array() || mat.size() != 12)
                r.fail(at + "/matrix", "expected 12 numbers: the rows of a 3x4 matrix");
            for (size_t k = 0; k < 12; ++k)
                transform.m[k] = r.number(mat[k], at + "/matrix/" + std::to_string(k));
        } else {
            if (inst.contains("scale")) {
                const json& sc = inst["scale"];
                const float3 f = sc.is_array() ? r.vec3(sc, at + "/scale")
                                               : make_float3(r.number(sc, at + "/scale"));
                transform = Matrix4x3{{f.x, 0, 0, 0, 0, f.y, 0, 0, 0, 0, f.z, 0}};
            }
            if (inst.contains("rotate")) {
                const json& rot = inst["rotate"];
                if (!rot.is_array() || rot.size() != 4)
                    r.fail(at + "/rotate", "expected [axis x, axis y, axis z, degrees]");
                const float3 axis = make_float3(r.number(rot[0], at + "/rotate/0"),
                                                r.number(rot[1], at + "/rotate/1"),
                                                r.number(rot[2], at + "/rotate/2"));
                if (!(length(axis) > 0)) r.fail(at + "/rotate", "the axis is zero");
                transform = multiply(rotation(axis, r.number(rot[3], at + "/rotate/3")), transform);
            }
            if (inst.contains("translate")) {
                const float3 t = r.vec3(inst["translate"], at + "/translate");
                transform.m[3] += t.x, transform.m[7] += t.y, transform.m[11] += t.z;
            }
        }
        Matrix4x3 inverse;
        if (!invert(transform, inverse))
            r.fail(at, "the transform is singular (a zero scale); rays could not enter it");
        placed[m] = true;
        for (unsigned k = mesh_range[m].first; k < mesh_range[m].second; ++k)
            scene.instances.push_back({k, transform});
    }
    for (size_t m = 0; m < placed.size(); ++m)
        if (!placed[m])
            r.fail("/meshes/" + std::to_string(m),
                   "no instance places this mesh; with \"instances\" only placed meshes are "
                   "drawn (add {\"mesh\": " + std::to_string(m) + "} or remove it)");
}
}  // namespace

namespace detail {
Scene read_json_scene(const std::string& path, const nlohmann::json& root,
                      const LoadProgress& progress);
}

Scene load_json_scene(const std::string& path, const LoadProgress& progress) {
    try {
        return detail::read_json_scene(path, parse_file(path), progress);
    } catch (const json::exception& e) {  // a value of a type the checks above did not expect
        throw Error(path + ": " + e.what());
    }
}

Scene detail::read_json_scene(const std::string& path, const nlohmann::json& root,
                              const LoadProgress& progress) {
    JsonReader r(path);
    if (!root.is_object())
        r.fail("/", "a scene is a JSON object with camera, materials, meshes, lights");
    r.only(root, {"camera", "materials", "meshes", "instances", "lights"}, "");

    Scene scene;
    scene.name = fs::path(path).stem().string();
    std::map<std::string, unsigned> material_ids;
    if (root.contains("materials")) {
        const json& list = root["materials"];
        if (!list.is_array()) r.fail("/materials", "expected an array of materials");
        for (size_t i = 0; i < list.size(); ++i) {
            const std::string at = "/materials/" + std::to_string(i);
            const json& m = list[i];
            r.only(m,
                   {"name", "diffuse", "specular", "shininess", "emission", "texture", "type",
                    "roughness", "ior"},
                   at);
            Material material;
            const json& name = r.member(m, "name", at);
            if (!name.is_string()) r.fail(at + "/name", "expected a string");
            material.name = name.get<std::string>();
            if (material_ids.count(material.name))
                r.fail(at + "/name", "a second material named '" + material.name + "'");
            if (m.contains("diffuse")) material.diffuse = r.vec3(m["diffuse"], at + "/diffuse");
            if (m.contains("specular")) material.specular = r.vec3(m["specular"], at + "/specular");
            if (m.contains("shininess"))
                material.shininess = r.number(m["shininess"], at + "/shininess");
            if (m.contains("emission")) material.emission = r.vec3(m["emission"], at + "/emission");
            if (m.contains("texture")) {
                if (!m["texture"].is_string()) r.fail(at + "/texture", "expected a file name");
                fs::path texture = r.resolve(m["texture"].get<std::string>());
                if (!fs::exists(texture))
                    r.fail(at + "/texture", "texture '" + texture.string() + "' not found");
                material.diffuse_texture = texture.string();
            }
            if (m.contains("type")) {
                const json& type = m["type"];
                if (type == "lambert")
                    material.kind = MaterialKind::kLambert;
                else if (type == "metal")
                    material.kind = MaterialKind::kMetal;
                else if (type == "dielectric")
                    material.kind = MaterialKind::kDielectric;
                else if (type == "coated")
                    material.kind = MaterialKind::kCoated;
                else
                    r.fail(at + "/type",
                           "expected \"lambert\", \"metal\", \"dielectric\" or \"coated\"");
            }
            if (m.contains("roughness")) {
                material.roughness = r.number(m["roughness"], at + "/roughness");
                if (!(material.roughness >= 0 && material.roughness <= 1))
                    r.fail(at + "/roughness", "expected a roughness in [0, 1]");
            }
            if (m.contains("ior")) {
                material.ior = r.number(m["ior"], at + "/ior");
                if (!(material.ior > 1 && material.ior <= 4))
                    r.fail(at + "/ior", "expected an index of refraction in (1, 4]");
            }
            material_ids[material.name] = unsigned(scene.materials.size());
            scene.materials.push_back(material);
        }
    }

    if (!root.contains("meshes") || !root["meshes"].is_array() || root["meshes"].empty())
        r.fail("/meshes", "a scene needs at least one mesh: [{\"file\": \"model.obj\"}]");
    const json& meshes = root["meshes"];
    // The Scene meshes each entry gives (an OBJ file gives one per object), for "instances".
    std::vector<std::pair<unsigned, unsigned>> mesh_range;
    for (size_t i = 0; i < meshes.size(); ++i) {
        const std::string at = "/meshes/" + std::to_string(i);
        const unsigned first_mesh = unsigned(scene.meshes.size());
        struct RangeEnd {  // records the entry's meshes however the loop body leaves
            std::vector<std::pair<unsigned, unsigned>>& ranges;
            const Scene& scene;
            unsigned first;
            ~RangeEnd() { ranges.push_back({first, unsigned(scene.meshes.size())}); }
        } range_end{mesh_range, scene, first_mesh};
        const json& m = meshes[i];
        r.only(m, {"file", "positions", "triangles", "material"}, at);
        int override_material = -1;
        if (m.contains("material")) {
            if (!m["material"].is_string() || !material_ids.count(m["material"].get<std::string>()))
                r.fail(at + "/material", "not the name of a material in /materials");
            override_material = int(material_ids[m["material"].get<std::string>()]);
        }
        if (m.contains("file")) {
            if (!m["file"].is_string()) r.fail(at + "/file", "expected a file name");
            const fs::path file = r.resolve(m["file"].get<std::string>());
            Scene part;
            if (file.extension() == ".ply") {
                part.meshes.push_back(load_ply_mesh(file.string(), progress));
                part.materials.push_back(
                    Material{"default", {0.8f, 0.8f, 0.8f}, {0, 0, 0}, 0, {0, 0, 0}, ""});
            } else {
                part = load_obj_scene(file.string(), progress);
            }
            const unsigned base = unsigned(scene.materials.size());
            scene.materials.insert(scene.materials.end(), part.materials.begin(),
                                   part.materials.end());
            for (Mesh& mesh : part.meshes) {
                for (unsigned& id : mesh.materials)
                    id = override_material >= 0 ? unsigned(override_material) : id + base;
                scene.meshes.push_back(std::move(mesh));
            }
            continue;
        }
        Mesh mesh;
        mesh.name = "mesh" + std::to_string(i);
        const json& positions = r.member(m, "positions", at);
        const json& triangles = r.member(m, "triangles", at);
        if (!positions.is_array() || !triangles.is_array() || triangles.empty())
            r.fail(
                at,
                "an inline mesh has \"positions\" [[x,y,z], ...] and \"triangles\" [[i,j,k], ...]");
        for (size_t p = 0; p < positions.size(); ++p)
            mesh.positions.push_back(r.vec3(positions[p], at + "/positions/" + std::to_string(p)));
        if (override_material < 0) {
            override_material = int(scene.materials.size());
            scene.materials.push_back(
                Material{"default", {0.8f, 0.8f, 0.8f}, {0, 0, 0}, 0, {0, 0, 0}, ""});
        }
        for (size_t t = 0; t < triangles.size(); ++t) {
            const std::string where = at + "/triangles/" + std::to_string(t);
            const json& tri = triangles[t];
            if (!tri.is_array() || tri.size() != 3) r.fail(where, "expected 3 vertex indices");
            unsigned idx[3];
            for (int k = 0; k < 3; ++k) {
                if (!tri[k].is_number_integer() || tri[k].get<long long>() < 0 ||
                    tri[k].get<long long>() >= (long long)mesh.positions.size())
                    r.fail(where + "/" + std::to_string(k),
                           "expected a vertex index in 0.." +
                               std::to_string(mesh.positions.size()) + " (exclusive)");
                idx[k] = tri[k].get<unsigned>();
            }
            mesh.indices.push_back(uint3{idx[0], idx[1], idx[2]});
            mesh.materials.push_back(unsigned(override_material));
        }
        scene.meshes.push_back(std::move(mesh));
    }

    if (root.contains("instances")) read_instances(r, root["instances"], mesh_range, scene);

    if (root.contains("lights")) {
        const json& lights = root["lights"];
        if (!lights.is_array()) r.fail("/lights", "expected an array of lights");
        for (size_t i = 0; i < lights.size(); ++i) {
            const std::string at = "/lights/" + std::to_string(i);
            const json& l = lights[i];
            const json& type = r.member(l, "type", at);
            if (type == "point") {
                r.only(l, {"type", "position", "intensity"}, at);
                scene.point_lights.push_back(
                    {r.vec3(r.member(l, "position", at), at + "/position"),
                     r.vec3(r.member(l, "intensity", at), at + "/intensity")});
            } else if (type == "area") {
                r.only(l, {"type", "corner", "edge1", "edge2", "emission"}, at);
                scene.area_lights.push_back(
                    {r.vec3(r.member(l, "corner", at), at + "/corner"),
                     r.vec3(r.member(l, "edge1", at), at + "/edge1"),
                     r.vec3(r.member(l, "edge2", at), at + "/edge2"),
                     r.vec3(r.member(l, "emission", at), at + "/emission")});
            } else {
                r.fail(at + "/type", "expected \"point\" or \"area\"");
            }
        }
    }

    if (!root.contains("camera")) {  // none given: one that frames the scene
        if (scene.triangle_count() == 0) r.fail("/camera", "a scene without triangles needs a camera");
        scene.camera = framing_camera(scene);
        return scene;
    }
    const json& camera = root["camera"];
    r.only(camera, {"eye", "look", "up", "fov"}, "/camera");
    scene.camera.eye = r.vec3(r.member(camera, "eye", "/camera"), "/camera/eye");
    scene.camera.look = r.vec3(r.member(camera, "look", "/camera"), "/camera/look");
    if (camera.contains("up")) scene.camera.up = r.vec3(camera["up"], "/camera/up");
    if (camera.contains("fov")) {
        scene.camera.fov_degrees = r.number(camera["fov"], "/camera/fov");
        if (!(scene.camera.fov_degrees > 0 && scene.camera.fov_degrees < 180))
            r.fail("/camera/fov", "expected a vertical field of view in (0, 180) degrees");
    }
    if (length(scene.camera.look - scene.camera.eye) == 0)
        r.fail("/camera", "eye and look are the same point");
    if (up_along_view(scene.camera))
        r.fail(camera.contains("up") ? "/camera/up" : "/camera",
               "up is zero or along the view direction from eye to look; give an up at an angle "
               "to it (e.g. [0, 1, 0] for a horizontal view, [0, 0, 1] looking straight down)");
    return scene;
}

}  // namespace lucent::scene

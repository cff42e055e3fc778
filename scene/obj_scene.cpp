// A Scene from an OBJ file and its MTL materials: vertices unified per (position, normal,
// uv) triple, polygons fanned into triangles, every error pointing at its file and line.
#include <cmath>
#include <filesystem>
#include <fstream>

#include "lucent/error.h"
#include "scene/input_file.h"
#include "scene/obj_reader.h"
#include "scene/scene.h"
#include "scene/vertex_unifier.h"

namespace lucent::scene {

namespace {
namespace fs = std::filesystem;

/// The file and line where `statement` (e.g. "map_Kd wood.png") stands among `files`.
std::string locate(const std::vector<std::string>& files, const std::string& keyword,
                   const std::string& value) {
    for (const std::string& file : files) {
        std::ifstream in(file);
        std::string line;
        for (size_t n = 1; std::getline(in, line); ++n)
            if (line.find(keyword) != std::string::npos && line.find(value) != std::string::npos)
                return file + ":" + std::to_string(n);
    }
    return files.empty() ? std::string("(no MTL file)") : files.front() + ":0";
}

float3 to_float3(const tinyobj::real_t v[3]) {
    return make_float3(v[0], v[1], v[2]);
}
}  // namespace

Scene load_obj_scene(const std::string& path, const LoadProgress& progress) {
    require_regular_file(path, "OBJ file");
    const ObjData obj = read_obj(path, /*with_materials=*/true, progress);
    for (const auto& [file, line] : obj.mtllibs)
        if (!fs::exists(file))
            fail(path, line,
                 "material library '" + fs::path(file).filename().string() +
                     "' not found next to the OBJ file");
    std::vector<std::string> mtl_files;
    for (const auto& lib : obj.mtllibs) mtl_files.push_back(lib.first);

    Scene scene;
    scene.name = fs::path(path).stem().string();
    for (const tinyobj::material_t& m : obj.materials) {
        Material material;
        material.name = m.name;
        material.diffuse = to_float3(m.diffuse);
        material.specular = to_float3(m.specular);
        material.shininess = m.shininess;
        material.emission = to_float3(m.emission);
        if (!m.diffuse_texname.empty()) {
            fs::path texture =
                fs::path(mtl_files.empty() ? path : mtl_files.front()).parent_path() /
                m.diffuse_texname;
            if (!fs::exists(texture))
                throw Error(locate(mtl_files, "map_Kd", m.diffuse_texname) + ": texture '" +
                            m.diffuse_texname + "' of material '" + m.name +
                            "' not found (paths are relative to the MTL file)");
            material.diffuse_texture = texture.string();
        }
        scene.materials.push_back(material);
    }
    const unsigned fallback = unsigned(scene.materials.size());  // faces without usemtl
    scene.materials.push_back(Material{"default", {0.8f, 0.8f, 0.8f}, {0, 0, 0}, 0, {0, 0, 0}, ""});

    const tinyobj::attrib_t& attrib = obj.attrib;
    const size_t vertex_count = attrib.vertices.size() / 3;
    size_t face = 0;
    VertexUnifier unified(vertex_count);
    for (const tinyobj::shape_t& shape : obj.shapes) {
        Mesh mesh;
        mesh.name = shape.name;
        unified.next_mesh();
        bool has_normals = !attrib.normals.empty(), has_uvs = !attrib.texcoords.empty();
        auto vertex = [&](const tinyobj::index_t& i) -> unsigned {
            if (i.vertex_index < 0 || size_t(i.vertex_index) >= vertex_count)
                fail(path, line_of_statement(path, "f", face),
                     "face refers to vertex " + std::to_string(i.vertex_index + 1) +
                         " but the file has " + std::to_string(vertex_count) + " vertices");
            if ((i.normal_index >= 0 && size_t(i.normal_index) >= attrib.normals.size() / 3) ||
                (i.texcoord_index >= 0 && size_t(i.texcoord_index) >= attrib.texcoords.size() / 2))
                fail(path, line_of_statement(path, "f", face),
                     "face refers to a normal or texture coordinate the file does not have");
            const auto [index, inserted] = unified.find(i.vertex_index, i.normal_index,
                                                        i.texcoord_index,
                                                        unsigned(mesh.positions.size()));
            if (inserted) {
                const float* p = &attrib.vertices[3 * size_t(i.vertex_index)];
                mesh.positions.push_back(make_float3(p[0], p[1], p[2]));
                if (has_normals) {
                    const float* n =
                        i.normal_index >= 0 ? &attrib.normals[3 * size_t(i.normal_index)] : nullptr;
                    mesh.normals.push_back(n ? make_float3(n[0], n[1], n[2])
                                             : make_float3(0, 0, 0));
                }
                if (has_uvs) {
                    const float* t = i.texcoord_index >= 0
                                         ? &attrib.texcoords[2 * size_t(i.texcoord_index)]
                                         : nullptr;
                    mesh.uvs.push_back(t ? make_float2(t[0], t[1]) : make_float2(0, 0));
                }
            }
            return index;
        };
        size_t offset = 0;
        for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f, ++face) {
            const size_t n = shape.mesh.num_face_vertices[f];
            const int id = shape.mesh.material_ids.empty() ? -1 : shape.mesh.material_ids[f];
            const unsigned material = id >= 0 && size_t(id) < fallback ? unsigned(id) : fallback;
            const unsigned first = vertex(shape.mesh.indices[offset]);
            for (size_t k = 1; k + 1 < n; ++k) {  // fan: convex polygons, as exporters write
                const unsigned b = vertex(shape.mesh.indices[offset + k]);
                const unsigned c = vertex(shape.mesh.indices[offset + k + 1]);
                mesh.indices.push_back(uint3{first, b, c});
                mesh.materials.push_back(material);
            }
            offset += n;
        }
        if (!mesh.indices.empty()) scene.meshes.push_back(std::move(mesh));
    }
    if (scene.triangle_count() == 0) fail(path, 0, "the OBJ file has no triangles");
    // Emissive triangles are what lights an OBJ scene (scene::emitter_lights); the camera
    // frames it, unless a JSON wrapper gives one.
    scene.camera = framing_camera(scene);
    return scene;
}

}  // namespace lucent::scene

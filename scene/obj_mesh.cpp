// OBJ geometry loading. tinyobjloader parses; this file triangulates and validates, and
// maps a bad vertex or face back to its line so the error points into the file.
#include "scene/obj_mesh.h"

#include <tiny_obj_loader.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <regex>

#include "lucent/error.h"

namespace lucent::scene {

namespace {

/// 1-based line of the n-th (0-based) statement starting with `tag` ("v" or "f"), or 0.
size_t line_of_statement(const std::string& path, const char* tag, size_t n) {
    std::ifstream in(path);
    std::string line;
    size_t line_no = 0, seen = 0;
    const size_t len = std::char_traits<char>::length(tag);
    while (std::getline(in, line)) {
        ++line_no;
        size_t s = line.find_first_not_of(" \t");
        if (s == std::string::npos || line.compare(s, len, tag) != 0) continue;
        if (s + len < line.size() && line[s + len] != ' ' && line[s + len] != '\t') continue;
        if (seen++ == n) return line_no;
    }
    return 0;
}

[[noreturn]] void fail(const std::string& path, size_t line, const std::string& message);

/// tinyobjloader reads "nan" or garbage as 0, so vertex coordinates are checked here,
/// with their line numbers.
void check_vertices(const std::string& path) {
    std::ifstream in(path);
    std::string line;
    size_t line_no = 0, vertex = 0;
    while (std::getline(in, line)) {
        ++line_no;
        size_t s = line.find_first_not_of(" \t");
        if (s == std::string::npos || line[s] != 'v' || s + 1 >= line.size() ||
            (line[s + 1] != ' ' && line[s + 1] != '\t'))
            continue;
        ++vertex;
        const char* p = line.c_str() + s + 1;
        for (int k = 0; k < 3; ++k) {
            char* end = nullptr;
            float x = std::strtof(p, &end);
            if (end == p || !std::isfinite(x))
                fail(path, line_no,
                     "vertex " + std::to_string(vertex) +
                         " has a coordinate that is not a finite "
                         "number: '" +
                         line.substr(s) + "'");
            p = end;
        }
    }
}

[[noreturn]] void fail(const std::string& path, size_t line, const std::string& message) {
    throw Error(path + ":" + std::to_string(line) + ": " + message);
}

}  // namespace

ObjMesh load_obj_mesh(const std::string& path) {
    {
        std::ifstream probe(path);
        if (!probe) fail(path, 0, "cannot open the OBJ file (check the path)");
    }
    check_vertices(path);
    tinyobj::ObjReaderConfig config;
    config.triangulate = false;  // fanned below, so a face maps back to its line
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path, config)) {
        std::string err = reader.Error();
        while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
        std::smatch m;
        size_t line = 0;
        if (std::regex_search(err, m, std::regex("line (\\d+)"))) line = std::stoul(m[1]);
        fail(path, line, "cannot parse OBJ: " + err);
    }

    ObjMesh mesh;
    const std::vector<float>& v = reader.GetAttrib().vertices;
    const size_t vertex_count = v.size() / 3;
    mesh.positions.resize(vertex_count);
    for (size_t i = 0; i < vertex_count; ++i) {
        float3 p = make_float3(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            fail(path, line_of_statement(path, "v", i),
                 "vertex " + std::to_string(i + 1) + " is not finite (NaN or infinity)");
        mesh.positions[i] = p;
    }

    size_t face = 0;  // faces in file order, across shapes
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        const tinyobj::mesh_t& m = shape.mesh;
        size_t offset = 0;
        for (size_t f = 0; f < m.num_face_vertices.size(); ++f, ++face) {
            const size_t n = m.num_face_vertices[f];
            for (size_t k = 0; k < n; ++k) {
                int idx = m.indices[offset + k].vertex_index;
                if (idx < 0 || (size_t)idx >= vertex_count)
                    fail(path, line_of_statement(path, "f", face),
                         "face refers to vertex " +
                             std::to_string(idx < 0 ? (long long)idx : (long long)idx + 1) +
                             " but the file has " + std::to_string(vertex_count) + " vertices");
            }
            // Fan triangulation (convex polygons, as OBJ exporters write them).
            for (size_t k = 1; k + 1 < n; ++k)
                mesh.indices.push_back(
                    make_uint3((unsigned)m.indices[offset].vertex_index,
                               (unsigned)m.indices[offset + k].vertex_index,
                               (unsigned)m.indices[offset + k + 1].vertex_index));
            offset += n;
        }
    }
    if (mesh.indices.empty()) fail(path, 0, "the OBJ file has no triangles");
    return mesh;
}

}  // namespace lucent::scene

// OBJ geometry for the benchmarks: positions and fanned triangles, validated.
#include "scene/obj_mesh.h"

#include "scene/obj_reader.h"

#include <tiny_obj_loader.h>

#include <cmath>

#include "lucent/error.h"

namespace lucent::scene {

ObjMesh load_obj_mesh(const std::string& path) {
    const ObjData obj = read_obj(path, /*with_materials=*/false);

    ObjMesh mesh;
    const std::vector<float>& v = obj.attrib.vertices;
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
    for (const tinyobj::shape_t& shape : obj.shapes) {
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

#include "core/triangle_gather.h"

#include <algorithm>

namespace lucent::core {

void gather_triangles(const CompiledScene& scene, const CompiledNode& node,
                      std::vector<float3>& vertices, std::vector<uint3>& indices,
                      std::vector<uint32_t>* tri_instance) {
    size_t vertex_total = 0, triangle_total = 0;
    for (unsigned i : node.instances) {
        const CompiledInstance& inst = scene.instances[i];
        vertex_total += inst.triangle_geometry()->vertices()->count();
        triangle_total += inst.primitive_count;
    }
    vertices.clear();
    indices.clear();
    vertices.reserve(vertex_total);
    indices.reserve(triangle_total);
    if (tri_instance) {
        tri_instance->clear();
        tri_instance->reserve(triangle_total);
    }
    for (unsigned k = 0; k < node.instances.size(); ++k) {
        const CompiledInstance& inst = scene.instances[node.instances[k]];
        const auto base = uint32_t(vertices.size());
        vertices.insert(vertices.end(), inst.vertices,
                        inst.vertices + inst.triangle_geometry()->vertices()->count());
        for (unsigned p = 0; p < inst.primitive_count; ++p) {
            const uint3 t = inst.triangle(p);
            indices.push_back(uint3{t.x + base, t.y + base, t.z + base});
        }
        if (tri_instance) tri_instance->insert(tri_instance->end(), inst.primitive_count, k);
    }
}

Aabb triangle_bounds(const CompiledScene& scene, const CompiledNode& node) {
    float lo[3] = {kInfinity, kInfinity, kInfinity}, hi[3] = {-kInfinity, -kInfinity, -kInfinity};
    auto grow = [&](float3 p) {
        lo[0] = std::min(lo[0], p.x), hi[0] = std::max(hi[0], p.x);
        lo[1] = std::min(lo[1], p.y), hi[1] = std::max(hi[1], p.y);
        lo[2] = std::min(lo[2], p.z), hi[2] = std::max(hi[2], p.z);
    };
    for (unsigned i : node.instances) {
        const CompiledInstance& inst = scene.instances[i];
        const float3* v = inst.vertices;
        const size_t vertex_count = inst.triangle_geometry()->vertices()->count();
        if (inst.primitive_count == 0) continue;
        if (vertex_count <= 3 * size_t(inst.primitive_count)) {
            // Every vertex of the buffer, in order, rather than through the indices (Sponza's
            // 66K triangles: 0.12 against 0.21 ms), when the buffer holds no more vertices
            // than the indices name. A vertex no triangle uses only makes the box larger,
            // which a box for culling may be.
            for (size_t j = 0; j < vertex_count; ++j) grow(v[j]);
        } else {
            // A buffer shared by instances that each use a part of it.
            for (unsigned p = 0; p < inst.primitive_count; ++p) {
                const uint3 t = inst.triangle(p);
                grow(v[t.x]), grow(v[t.y]), grow(v[t.z]);
            }
        }
    }
    return Aabb{make_float3(lo[0], lo[1], lo[2]), make_float3(hi[0], hi[1], hi[2])};
}

}  // namespace lucent::core

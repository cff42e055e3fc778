// A GeometryGroup of built-in triangles on the CPU: its accel numbers the triangles of all
// its instances together; these find a triangle's instance again, and fetch its data
// ahead of the shade phase that reads it.
#pragma once

#include "core/compiled_scene.h"

namespace lucent::cpu {

/// Global triangle `global` of a triangles-only group → (instance index, local index).
inline void locate_triangle(const core::CompiledNode& n, unsigned global, unsigned& instance,
                            unsigned& local) {
    const core::GeometryAccel& ga = *n.geometry;
    // One instance (the common case) needs no lookup: tri_instance[global] is a load from a
    // per-triangle array that a diffuse ray's random triangle misses in cache.
    const size_t k = n.instances.size() == 1 ? 0 : ga.tri_instance[global];
    instance = n.instances[k];
    local = global - ga.prim_first[k];
}

/// Starts loading the vertex indices of global triangle `global` (none: kStreamMiss).
inline void prefetch_triangle_indices(const core::CompiledScene& scene, const core::CompiledNode& n,
                                      unsigned global) {
    if (global == ~0u) return;
    unsigned instance, local;
    locate_triangle(n, global, instance, local);
    const core::CompiledInstance& inst = scene.instances[instance];
    if (inst.indices) __builtin_prefetch(&inst.indices[local]);
}

/// Starts loading the vertices of global triangle `global`; its indices should have
/// arrived (prefetch_triangle_indices, some rays earlier).
inline void prefetch_triangle_vertices(const core::CompiledScene& scene,
                                       const core::CompiledNode& n, unsigned global) {
    if (global == ~0u) return;
    unsigned instance, local;
    locate_triangle(n, global, instance, local);
    const core::CompiledInstance& inst = scene.instances[instance];
    const uint3 t = inst.triangle(local);
    __builtin_prefetch(&inst.vertices[t.x]);
    __builtin_prefetch(&inst.vertices[t.y]);
    __builtin_prefetch(&inst.vertices[t.z]);
}

}  // namespace lucent::cpu

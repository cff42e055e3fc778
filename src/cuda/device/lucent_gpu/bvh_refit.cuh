// Refit of the GPU triangle BVH layout (triangle_bvh.cuh) after its vertices moved: the
// topology stays, the triangles are copied again and every box is recomputed bottom-up.
// Each node waits for its two children with an atomic counter and the second to arrive
// goes on to the parent (Karras 2012, "Maximizing parallelism in the construction of
// BVHs, octrees, and k-d trees", Sec. 4). Launched by src/cuda/accel/gpu_bvh_builder.cpp; works
// on any layout with parent links, built on the host or by bvh_build.cuh.
#pragma once

#include "lucent/device/platform.h"
#include "lucent/device/types.h"
#include "lucent_gpu/triangle_bvh.cuh"

namespace lucent::gpu {

/// What the refit kernels read and write.
struct GpuRefitParams {
    const float3* positions;
    const uint3* indices;  // null: triangle i is positions[3i .. 3i + 2]
    unsigned vertex_count;
    unsigned triangle_count;
    unsigned node_count;
    float4* nodes;
    float4* triangles;
    const unsigned* triangle_ids;
    const unsigned* parents;
    unsigned* arrivals;  // node_count counters, zero on entry
};

#if LUCENT_GPU_CODE

constexpr unsigned kRefitNoParent = 0xffffffffu;

__device__ inline void kernel_refit_triangles(GpuRefitParams p) {
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= p.triangle_count) return;
    const unsigned t = p.triangle_ids[i];
    const uint3 v = p.indices ? p.indices[t] : make_uint3(3 * t, 3 * t + 1, 3 * t + 2);
    if (v.x >= p.vertex_count || v.y >= p.vertex_count || v.z >= p.vertex_count) return;
    gpu_store_triangle(p.triangles, i, p.positions[v.x], p.positions[v.y], p.positions[v.z]);
}

__device__ inline void set_slot_box(float4* node, unsigned slot, float3 lo, float3 hi) {
    if (slot == 0) {
        node[0] = make_float4(lo.x, hi.x, lo.y, hi.y);
        node[2].x = lo.z, node[2].y = hi.z;
    } else {
        node[1] = make_float4(lo.x, hi.x, lo.y, hi.y);
        node[2].z = lo.z, node[2].w = hi.z;
    }
}

/// One thread per node: boxes its leaf children, then climbs while it is the last of a
/// node's two children to arrive.
__device__ inline void kernel_refit_nodes(GpuRefitParams p) {
    unsigned node = blockIdx.x * blockDim.x + threadIdx.x;
    if (node >= p.node_count || p.triangle_count == 0) return;
    float4* at = p.nodes + kGpuNodeFloat4s * node;
    const float4 refs = at[3];
    const int ref[2] = {__float_as_int(refs.x), __float_as_int(refs.y)};
    const bool one_leaf_root = node == 0 && ref[0] == ref[1];  // second slot is the empty box
    unsigned leaves = 0;
    for (unsigned slot = 0; slot < 2; ++slot) {
        if (ref[slot] >= 0) continue;
        ++leaves;
        if (slot == 1 && one_leaf_root) continue;
        const unsigned first = gpu_leaf_first(ref[slot]), count = gpu_leaf_count(ref[slot]);
        float3 lo = make_float3(3.0e38f, 3.0e38f, 3.0e38f), hi = -lo;
        for (unsigned k = 0; k < 3 * count; ++k) {
            const float4 v = p.triangles[3 * first + k];
            lo = fminf(lo, make_float3(v.x, v.y, v.z));
            hi = fmaxf(hi, make_float3(v.x, v.y, v.z));
        }
        set_slot_box(at, slot, lo, hi);
    }
    if (leaves == 0) return;  // its children arrive by climbing
    if (leaves == 1) {
        __threadfence();  // the leaf's box is visible before the arrival is counted
        if (atomicAdd(&p.arrivals[node], 1u) == 0) return;
    }
    for (;;) {  // every child of `node` is boxed: box it in its parent
        const unsigned up = p.parents[node];
        if (up == kRefitNoParent) return;
        __threadfence();
        const float4 xy0 = __ldcg(&at[0]), xy1 = __ldcg(&at[1]), z = __ldcg(&at[2]);
        // Slot boxes are stored (lo.x, hi.x, lo.y, hi.y) and z as (lo0, hi0, lo1, hi1).
        const float3 lo = make_float3(fminf(xy0.x, xy1.x), fminf(xy0.z, xy1.z), fminf(z.x, z.z));
        const float3 hi = make_float3(fmaxf(xy0.y, xy1.y), fmaxf(xy0.w, xy1.w), fmaxf(z.y, z.w));
        node = up >> 1;
        at = p.nodes + kGpuNodeFloat4s * node;
        set_slot_box(at, up & 1u, lo, hi);
        __threadfence();
        // Two arrivals complete a node: its inner children climbing, or its own thread for
        // its one leaf child. The first stops, the second goes on.
        if (atomicAdd(&p.arrivals[node], 1u) == 0) return;
    }
}

#endif  // LUCENT_GPU_CODE

}  // namespace lucent::gpu

#if LUCENT_GPU_CODE
// The entry points the host launches (extern "C": unmangled names for cuModuleGetFunction).
extern "C" __global__ void lucent_refit_triangles(lucent::gpu::GpuRefitParams p) {
    lucent::gpu::kernel_refit_triangles(p);
}
extern "C" __global__ void lucent_refit_nodes(lucent::gpu::GpuRefitParams p) {
    lucent::gpu::kernel_refit_nodes(p);
}
#endif  // LUCENT_GPU_CODE

// The GPU binned-SAH builder's passes 6 and 7 (bvh_sah_build.cuh): every subtree's inner
// nodes and SAH cost, bottom-up, then the depth-first layout of triangle_bvh.cuh.
#pragma once

#include "lucent_gpu/bvh_sah_helpers.cuh"

namespace lucent::gpu {

// ---- 6: subtree counts and costs, bottom-up ---------------------------------------------------

/// One thread per node; leaves climb, the second child to arrive at a node goes on (the
/// refit's pattern).
LUCENT_HD inline void sah_count(const GpuSahBuildParams& p, unsigned x) {
    if (x >= p.counters[kSahNextNode]) return;
    const uint2 r = p.node_range[x];
    if (r.y == 0) return;  // inner: reached from its children
    {
        const float a = sah_half_area(sah_xyz(p.node_lo[x]), sah_xyz(p.node_hi[x]));
        p.node_lo[x].w = sah_mul(sah_mul(p.intersection_cost, (float)r.y), a);
        p.node_inner[x] = 0;
    }
    for (unsigned parent = p.node_parent[x]; parent != kSahInvalid; parent = p.node_parent[x]) {
        sah_fence();  // our subtree's figures are visible before we arrive
        if (sah_atomic_add(&p.node_arrivals[parent], 1u) == 0) return;  // the first waits
        sah_fence();
        const unsigned c0 = p.node_range[parent].x;
#if LUCENT_GPU_CODE
        const float cost0 = __ldcg(&p.node_lo[c0].w), cost1 = __ldcg(&p.node_lo[c0 + 1].w);
        const unsigned inner0 = __ldcg(&p.node_inner[c0]), inner1 = __ldcg(&p.node_inner[c0 + 1]);
#else
        const float cost0 = p.node_lo[c0].w, cost1 = p.node_lo[c0 + 1].w;
        const unsigned inner0 = p.node_inner[c0], inner1 = p.node_inner[c0 + 1];
#endif
        const float a = sah_half_area(sah_xyz(p.node_lo[parent]), sah_xyz(p.node_hi[parent]));
        p.node_lo[parent].w = sah_add(sah_mul(p.traversal_cost, a), sah_add(cost0, cost1));
        p.node_inner[parent] = 1 + inner0 + inner1;
        x = parent;
    }
}

// ---- 7: the layout ----------------------------------------------------------------------------

LUCENT_HD inline float4 sah_box_xy(float4 lo, float4 hi) {
    return make_float4(lo.x, hi.x, lo.y, hi.y);
}

/// One thread per node; inner nodes write their node of the depth-first layout. A root that
/// is a leaf (a few triangles) gets a second, empty box, as the host's layout.
LUCENT_HD inline void sah_emit(const GpuSahBuildParams& p, unsigned x) {
    if (x >= p.counters[kSahNextNode]) return;
    const uint2 r = p.node_range[x];
    const float4 empty_xy = make_float4(kSahEmpty, -kSahEmpty, kSahEmpty, -kSahEmpty);
    if (x == 0 && r.y > 0) {
        const float4 lo = p.node_lo[0], hi = p.node_hi[0];
        p.out_nodes[0] = sah_box_xy(lo, hi);
        p.out_nodes[1] = empty_xy;
        p.out_nodes[2] = make_float4(lo.z, hi.z, kSahEmpty, -kSahEmpty);
        const int leaf = gpu_make_leaf(r.x, r.y);
#if LUCENT_GPU_CODE
        const float leaf_bits = __int_as_float(leaf);
#else
        const float leaf_bits = std::bit_cast<float>(leaf);
#endif
        p.out_nodes[3] = make_float4(leaf_bits, leaf_bits, 0.0f, 0.0f);
        p.out_parents[0] = kSahInvalid;
        p.counters[kSahDepth] = 1;
        p.counters[kSahInner] = 1;
        const float a = sah_half_area(sah_xyz(lo), sah_xyz(hi));
        p.counters[kSahCost] = sah_float_bits(a > 0.0f ? lo.w / a : lo.w);
        return;
    }
    if (r.y > 0) return;  // a leaf: its parent writes it
    // Our place in depth-first order: 1 past the parent for child 0, past the parent and all
    // of child 0's inner nodes for child 1.
    unsigned index = 0, depth = 1;
    for (unsigned c = x, parent = p.node_parent[x]; parent != kSahInvalid;
         c = parent, parent = p.node_parent[parent]) {
        const unsigned c0 = p.node_range[parent].x;
        index += c == c0 ? 1u : 1u + p.node_inner[c0];
        if (++depth >= (unsigned)kGpuStackSize) {
            sah_atomic_first(&p.counters[kSahFault], kSahFaultDeepTree);
            return;
        }
    }
    const unsigned c0 = r.x, c1 = r.x + 1;
    const float4 lo0 = p.node_lo[c0], hi0 = p.node_hi[c0], lo1 = p.node_lo[c1], hi1 = p.node_hi[c1];
    float4* out = p.out_nodes + kGpuNodeFloat4s * index;
    out[0] = sah_box_xy(lo0, hi0);
    out[1] = sah_box_xy(lo1, hi1);
    out[2] = make_float4(lo0.z, hi0.z, lo1.z, hi1.z);
    const uint2 r0 = p.node_range[c0], r1 = p.node_range[c1];
    const unsigned index0 = index + 1, index1 = index + 1 + p.node_inner[c0];
    int ref0, ref1;
    if (r0.y > 0) {
        ref0 = gpu_make_leaf(r0.x, r0.y);
    } else {
        ref0 = (int)(kGpuNodeFloat4s * index0);
        p.out_parents[index0] = index << 1;
    }
    if (r1.y > 0) {
        ref1 = gpu_make_leaf(r1.x, r1.y);
    } else {
        ref1 = (int)(kGpuNodeFloat4s * index1);
        p.out_parents[index1] = index << 1 | 1u;
    }
#if LUCENT_GPU_CODE
    out[3] = make_float4(__int_as_float(ref0), __int_as_float(ref1), 0.0f, 0.0f);
#else
    out[3] = make_float4(std::bit_cast<float>(ref0), std::bit_cast<float>(ref1), 0.0f, 0.0f);
#endif
    sah_atomic_max(&p.counters[kSahDepth], depth);
    if (index == 0) {
        p.out_parents[0] = kSahInvalid;
        const float a = sah_half_area(sah_xyz(p.node_lo[x]), sah_xyz(p.node_hi[x]));
        p.counters[kSahCost] = sah_float_bits(a > 0.0f ? p.node_lo[x].w / a : p.node_lo[x].w);
        p.counters[kSahInner] = p.node_inner[x];
    }
}

/// One thread per place of the leaf order: the triangle's three vertices and its id.
LUCENT_HD inline void sah_triangles(const GpuSahBuildParams& p, unsigned at) {
    if (at >= p.triangle_count) return;
    const unsigned t = p.order[at];
    const uint3 v = sah_triangle(p, t);
    const bool ok = v.x < p.vertex_count && v.y < p.vertex_count && v.z < p.vertex_count;
    const float3 a = ok ? p.positions[v.x] : make_float3(0.0f, 0.0f, 0.0f);
    const float3 b = ok ? p.positions[v.y] : a, c = ok ? p.positions[v.z] : a;
    gpu_store_triangle(p.out_triangles, at, a, b, c);
    p.out_triangle_ids[at] = t;
}

}  // namespace lucent::gpu

// GPU layout of a compressed 8-wide triangle BVH and its single-ray traversal, after
// Ylitie, Karras and Laine 2017, "Efficient incoherent ray traversal on GPUs through
// compressed wide BVHs" (HPG 2017):
//
//  - 8 children per node, chosen by the optimal collapse of a binned-SAH binary BVH
//    (accel::WideCollapse, Sec. 3.1 of the paper);
//  - 80-byte nodes (five float4): the children's boxes quantized to 8 bits per plane on a
//    grid of the node's own (Sec. 3.2), the children that are nodes stored together from
//    one index, and the triangles of the children that are leaves stored together from
//    another, so a node names its children with two indices and eight bytes;
//  - triangles in leaf order, three float4 each, as in the binary layout (triangle_bvh.cuh).
//
// The grid is chosen so that every decoded plane, origin + q * 2^e, is a float computed
// without rounding (the origin is a multiple of 2^e, and origin / 2^e + 255 < 2^24): the
// decoded box is then an ordinary box of floats, rounded outwards at build time, and the box
// test is the binary layout's (GpuBvhTraversal::slab), so the two layouts find the same hits.
//
// This traversal sorts each node's hit children by distance and keeps them on a stack; it is
// the reference the layout is checked with on the CPU (tests/gpu_cwbvh_test.cpp), the same
// code a kernel runs. The paper's node-group stack and octant-ordered child slots, which
// matter on the GPU, are not here yet.
#pragma once

#include "lucent/device/platform.h"
#include "lucent/device/triangle_intersect.h"
#include "lucent/device/vector_math.h"
#include "lucent_gpu/triangle_bvh.cuh"

namespace lucent::gpu {

// ---- layout -------------------------------------------------------------------------
//
// Node n occupies nodes[5n .. 5n + 4]:
//   [5n + 0] = (origin.x, origin.y, origin.z, bits: ex | ey << 8 | ez << 16 | inner << 24)
//   [5n + 1] = (bits: child_base, triangle_base, meta[0..3], meta[4..7])
//   [5n + 2] = (bits: qlo.x[0..3], qlo.x[4..7], qhi.x[0..3], qhi.x[4..7])
//   [5n + 3] = the same for y, [5n + 4] for z
// e is the biased exponent of the grid step 2^(e - 127) on each axis; a plane is
// origin + q * 2^(e - 127) for its byte q. `inner` has bit i set when slot i is a node: the
// node at child_base + (the number of node slots before i). meta[i] is the paper's: 0 for an
// empty slot, 0b001 << 5 | (24 + i) for a node, and for a leaf its triangle count in unary
// in the top three bits (0b001, 0b011, 0b111) above the offset of its first triangle from
// triangle_base (< 24). (meta >> 5) << (meta & 31) is then the bit (a node: 24 + i) or the
// bits (a leaf: one per triangle) a hit child adds to the paper's hit mask. Node 0 is the
// root. An empty slot has qlo = 255 and qhi = 0, a box turned inside out no ray enters.
//
// Slots are assigned by the children's positions in the node (Sec. 3.2 of the paper): slot s
// holds a child near the corner whose coordinates are high on the axes of the bits of s, so a
// ray whose direction has negative components on the axes of the bits of o meets the
// children roughly in the order of s ^ o, a front-to-back order without a sort.

constexpr int kCwbvhNodeFloat4s = 5;
constexpr int kCwbvhArity = 8;
constexpr int kCwbvhMaxLeafSize = 3;             // a unary count in three bits
constexpr unsigned kCwbvhMaxNodeTriangles = 24;  // leaf triangles per node: offsets < 24
constexpr unsigned kCwbvhInnerBit = 24;          // a node child's bit in the hit mask: 24 + slot
constexpr int kCwbvhQuantMax = 255;
// Entries: each node pushes at most 7, and the wide tree is no deeper than the binary one
// (the builder caps that at 60).
constexpr int kCwbvhStackSize = (kCwbvhArity - 1) * 64 + 1;

/// Device pointers of one uploaded GpuCwbvh (same layout on host and device).
struct GpuCwbvhView {
    const float4* nodes;
    const float4* triangles;
    const unsigned* triangle_ids;
};

LUCENT_HD inline unsigned cwbvh_bits(float f) {
    return (unsigned)gpu_float_as_int(f);
}
LUCENT_HD inline unsigned cwbvh_byte(unsigned word, int i) {
    return (word >> (8 * i)) & 0xffu;
}
LUCENT_HD inline int cwbvh_popc(unsigned x) {
#if LUCENT_GPU_CODE
    return __popc(x);
#else
    return __builtin_popcount(x);
#endif
}
/// The grid step 2^(e - 127) of a biased exponent e in 1..254.
LUCENT_HD inline float cwbvh_step(unsigned biased_exponent) {
#if LUCENT_GPU_CODE
    return __int_as_float((int)(biased_exponent << 23));
#else
    return __builtin_bit_cast(float, biased_exponent << 23);
#endif
}

/// One node, loaded and split into the fields the traversal reads.
struct GpuCwbvhNode {
    float3 origin, step;
    unsigned inner, child_base, triangle_base;
    unsigned meta[2];
    unsigned q[3][4];  // per axis: qlo[0..3], qlo[4..7], qhi[0..3], qhi[4..7]

    LUCENT_HD static GpuCwbvhNode load(const float4* nodes, unsigned index) {
        const float4* p = nodes + (size_t)kCwbvhNodeFloat4s * index;
        const float4 a = gpu_load(p + 0), b = gpu_load(p + 1);
        GpuCwbvhNode n;
        n.origin = make_float3(a.x, a.y, a.z);
        const unsigned packed = cwbvh_bits(a.w);
        n.step = make_float3(cwbvh_step(cwbvh_byte(packed, 0)), cwbvh_step(cwbvh_byte(packed, 1)),
                             cwbvh_step(cwbvh_byte(packed, 2)));
        n.inner = cwbvh_byte(packed, 3);
        n.child_base = cwbvh_bits(b.x);
        n.triangle_base = cwbvh_bits(b.y);
        n.meta[0] = cwbvh_bits(b.z);
        n.meta[1] = cwbvh_bits(b.w);
        for (int k = 0; k < 3; ++k) {
            const float4 c = gpu_load(p + 2 + k);
            n.q[k][0] = cwbvh_bits(c.x), n.q[k][1] = cwbvh_bits(c.y);
            n.q[k][2] = cwbvh_bits(c.z), n.q[k][3] = cwbvh_bits(c.w);
        }
        return n;
    }

    LUCENT_HD unsigned slot_meta(int i) const { return cwbvh_byte(meta[i >> 2], i & 3); }

    /// The box of slot i, exactly as the builder decoded it: origin + q * step, one FMA
    /// whose result is representable (see the file comment), so it is not rounded.
    LUCENT_HD void child_box(int i, float3& lo, float3& hi) const {
        const int word = i >> 2, byte = i & 3;
        const float o[3] = {origin.x, origin.y, origin.z}, s[3] = {step.x, step.y, step.z};
        float l[3], h[3];
        for (int k = 0; k < 3; ++k) {
            l[k] = fmaf((float)cwbvh_byte(q[k][word], byte), s[k], o[k]);
            h[k] = fmaf((float)cwbvh_byte(q[k][word + 2], byte), s[k], o[k]);
        }
        lo = make_float3(l[0], l[1], l[2]);
        hi = make_float3(h[0], h[1], h[2]);
    }

    /// The reference of slot i: a node index (>= 0) or a leaf (gpu_make_leaf, < 0).
    LUCENT_HD int child_ref(int i) const {
        const unsigned m = slot_meta(i);
        if (inner & (1u << i))
            return (int)(child_base + (unsigned)cwbvh_popc(inner & ((1u << i) - 1u)));
        return gpu_make_leaf(triangle_base + (m & 0x1fu), (unsigned)cwbvh_popc(m >> 5));
    }
};

// ---- traversal ---------------------------------------------------------------------

/// The traversal stack of one ray: references and their entry distances.
struct GpuCwbvhStack {
    int ref[kCwbvhStackSize];
    float t[kCwbvhStackSize];
};

/// One ray's box-test terms, in the fields GpuBvhTraversal::slab reads.
struct GpuCwbvhRay {
    float idx, idy, idz, olox, oloy, oloz, ohix, ohiy, ohiz, tmin, tmax;

    LUCENT_HD void start(float3 origin, float3 dir, float t0, float t1) {
        GpuBvhTraversal::axis_terms(origin.x, dir.x, idx, olox, ohix);
        GpuBvhTraversal::axis_terms(origin.y, dir.y, idy, oloy, ohiy);
        GpuBvhTraversal::axis_terms(origin.z, dir.z, idz, oloz, ohiz);
        tmin = t0;
        tmax = t1;
    }
};

/// Closest (kGpuClosest), any (kGpuAny) or filtered (kGpuFiltered) hit with t in
/// (tmin, tmax), nearer children first. Returns whether a hit was found (accepted) and, for
/// closest and filtered queries, writes it to `out`.
template <int kQuery, class Filter>
LUCENT_HD inline bool gpu_cwbvh_trace(const GpuCwbvhView& bvh, float3 origin, float3 dir,
                                      float tmin, float tmax, GpuHit& out, Filter& filter,
                                      GpuCwbvhStack& stack) {
    GpuCwbvhRay ray;
    ray.start(origin, dir, tmin, tmax);
    const WatertightRay wt = make_watertight_ray(origin, dir);
    int hit_index = -1;
    float hit_u = 0.0f, hit_v = 0.0f;
    int sp = 0;
    int ref = 0;  // the root
    for (;;) {
        if (ref >= 0) {
            const GpuCwbvhNode node = GpuCwbvhNode::load(bvh.nodes, (unsigned)ref);
            // The children hit, sorted by entry distance, farthest first.
            int refs[kCwbvhArity];
            float ts[kCwbvhArity];
            int count = 0;
            for (int i = 0; i < kCwbvhArity; ++i) {
                if (node.slot_meta(i) == 0u) continue;
                float3 lo, hi;
                node.child_box(i, lo, hi);
                float t_near, t_far;
                GpuBvhTraversal::slab(lo.x, hi.x, lo.y, hi.y, lo.z, hi.z, ray, t_near, t_far);
                if (!(t_near <= t_far)) continue;
                int j = count++;
                while (j > 0 && ts[j - 1] < t_near) {
                    ts[j] = ts[j - 1];
                    refs[j] = refs[j - 1];
                    --j;
                }
                ts[j] = t_near;
                refs[j] = node.child_ref(i);
            }
            if (count > 0) {
                for (int j = 0; j < count - 1; ++j) {
                    stack.ref[sp] = refs[j];
                    stack.t[sp++] = ts[j];
                }
                ref = refs[count - 1];
                continue;
            }
        } else {
            const unsigned first = gpu_leaf_first(ref);
            const unsigned end = first + gpu_leaf_count(ref);
            for (unsigned i = first; i < end; ++i) {
                float t, u, v;
                if (!gpu_intersect_triangle(bvh.triangles, i, wt, ray.tmin, ray.tmax, t, u, v))
                    continue;
                if constexpr (kQuery == kGpuAny) return true;
                if constexpr (kQuery == kGpuFiltered) {
                    const GpuHit candidate{t, u, v, bvh.triangle_ids[i]};
                    const int decision = filter(candidate);
                    if (decision == kGpuIgnore) continue;
                    if (decision == kGpuAcceptAndStop) {
                        out = candidate;
                        return true;
                    }
                }
                ray.tmax = t;
                hit_index = (int)i;
                hit_u = u;
                hit_v = v;
            }
        }
        // The next entry that may still hold a nearer hit.
        for (;;) {
            if (sp == 0) {
                if (hit_index < 0) return false;
                out.t = ray.tmax;
                out.u = hit_u;
                out.v = hit_v;
                out.prim = bvh.triangle_ids[hit_index];
                return true;
            }
            --sp;
            if (kQuery == kGpuAny || stack.t[sp] <= ray.tmax) break;
        }
        ref = stack.ref[sp];
    }
}

/// Closest hit with t in (tmin, tmax).
LUCENT_HD inline bool gpu_cwbvh_closest(const GpuCwbvhView& bvh, float3 origin, float3 dir,
                                        float tmin, float tmax, GpuHit& hit) {
    GpuCwbvhStack stack;
    GpuNoFilter none;
    return gpu_cwbvh_trace<kGpuClosest>(bvh, origin, dir, tmin, tmax, hit, none, stack);
}

/// True when any triangle is hit with t in (tmin, tmax); stops at the first.
LUCENT_HD inline bool gpu_cwbvh_occluded(const GpuCwbvhView& bvh, float3 origin, float3 dir,
                                         float tmin, float tmax) {
    GpuCwbvhStack stack;
    GpuNoFilter none;
    GpuHit unused;
    return gpu_cwbvh_trace<kGpuAny>(bvh, origin, dir, tmin, tmax, unused, none, stack);
}

/// Closest accepted hit, each candidate nearer than the closest accepted one first offered
/// to filter(const GpuHit&) -> kGpuIgnore / kGpuAccept / kGpuAcceptAndStop.
template <class Filter>
LUCENT_HD inline bool gpu_cwbvh_filtered(const GpuCwbvhView& bvh, float3 origin, float3 dir,
                                         float tmin, float tmax, GpuHit& hit, Filter&& filter) {
    GpuCwbvhStack stack;
    return gpu_cwbvh_trace<kGpuFiltered>(bvh, origin, dir, tmin, tmax, hit, filter, stack);
}

}  // namespace lucent::gpu

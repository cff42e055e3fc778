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
// The traversal is the paper's (Sec. 3.3): groups of children, taken in the order the slots'
// octant assignment gives, and one stack entry per level. The CPU runs the very same code to
// check the layout (tests/gpu_cwbvh_test.cpp); the paper's warp-level postponing of triangle
// tests is a GPU tuning not done yet.
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
/// Byte i of `word` as a float, exactly: the float whose bits are 2^23's with the byte as its
/// low mantissa bits is 2^23 + q, so one subtraction gives q without an integer-to-float
/// conversion (a quarter-rate instruction on the GPU, and six per child).
LUCENT_HD inline float cwbvh_byte_float(unsigned word, int i) {
    const unsigned bits = 0x4B000000u | cwbvh_byte(word, i);
#if LUCENT_GPU_CODE
    return __uint_as_float(bits) - 8388608.0f;
#else
    return __builtin_bit_cast(float, bits) - 8388608.0f;
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

/// The traversal stack of one ray: node groups, each the children of one node still to be
/// visited (the paper's Sec. 3.3). A node pushes at most one group, so the depth of the tree
/// bounds the stack (the builder caps the binary tree, deeper than the wide one, at 60).
struct GpuCwbvhStack {
    unsigned base[kGpuStackSize];  // child_base of the node the group belongs to
    unsigned bits[kGpuStackSize];  // its `inner` mask << 8 | the children still to visit
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
    /// The octant of the direction, a bit per axis set where it is negative (as the slab
    /// test sees it: the sign of the clamped 1/d).
    LUCENT_HD unsigned octant() const {
        return (idx < 0.0f ? 1u : 0u) | (idy < 0.0f ? 2u : 0u) | (idz < 0.0f ? 4u : 0u);
    }
};

LUCENT_HD inline unsigned cwbvh_highest_bit(unsigned x) {
#if LUCENT_GPU_CODE
    return 31u - (unsigned)__clz(x);
#else
    return 31u - (unsigned)__builtin_clz(x);
#endif
}
LUCENT_HD inline unsigned cwbvh_lowest_bit(unsigned x) {
#if LUCENT_GPU_CODE
    return (unsigned)(__ffs(x) - 1);
#else
    return (unsigned)__builtin_ctz(x);
#endif
}

/// The hit mask of a node's children (the paper's): a node child in slot i that the ray
/// enters sets bit 24 + (i ^ oct_inv), a leaf child its triangles' bits (one each, from its
/// offset). Taking node bits highest first then visits the children roughly front to back.
///
/// The test is GpuBvhTraversal::slab's, reorganised for eight children: per axis, the words
/// of the near planes (lo where the direction is positive, hi where negative) are chosen
/// once per node rather than once per child, and all eight slots are tested without a
/// branch (an empty slot's box is inside out, so it is never entered, and its meta is 0).
LUCENT_HD inline unsigned cwbvh_intersect_children(const GpuCwbvhNode& node, const GpuCwbvhRay& ray,
                                                   unsigned oct_inv) {
    // slab() subtracts olo for lo planes and ohi for hi planes: the near offset is the lo
    // one where the direction is positive.
    const bool nx = ray.idx < 0.0f, ny = ray.idy < 0.0f, nz = ray.idz < 0.0f;
    const float onx = nx ? ray.ohix : ray.olox, ofx = nx ? ray.olox : ray.ohix;
    const float ony = ny ? ray.ohiy : ray.oloy, ofy = ny ? ray.oloy : ray.ohiy;
    const float onz = nz ? ray.ohiz : ray.oloz, ofz = nz ? ray.oloz : ray.ohiz;
    unsigned hits = 0;
    // Slots 4 * word .. 4 * word + 3, whose planes are in word `word` of each axis's lo and hi
    // words: the near planes' word is the hi one where the direction is negative.
    auto four_slots = [&](int word) {
        const unsigned near_x = nx ? node.q[0][2 + word] : node.q[0][word];
        const unsigned far_x = nx ? node.q[0][word] : node.q[0][2 + word];
        const unsigned near_y = ny ? node.q[1][2 + word] : node.q[1][word];
        const unsigned far_y = ny ? node.q[1][word] : node.q[1][2 + word];
        const unsigned near_z = nz ? node.q[2][2 + word] : node.q[2][word];
        const unsigned far_z = nz ? node.q[2][word] : node.q[2][2 + word];
#if LUCENT_GPU_CODE
#pragma unroll
#endif
        for (int byte = 0; byte < 4; ++byte) {
            auto plane = [&](unsigned w, float origin, float step) {
                return fmaf(cwbvh_byte_float(w, byte), step, origin);  // exact (file comment)
            };
            const float tnx = fmaf(plane(near_x, node.origin.x, node.step.x), ray.idx, -onx);
            const float tfx = fmaf(plane(far_x, node.origin.x, node.step.x), ray.idx, -ofx);
            const float tny = fmaf(plane(near_y, node.origin.y, node.step.y), ray.idy, -ony);
            const float tfy = fmaf(plane(far_y, node.origin.y, node.step.y), ray.idy, -ofy);
            const float tnz = fmaf(plane(near_z, node.origin.z, node.step.z), ray.idz, -onz);
            const float tfz = fmaf(plane(far_z, node.origin.z, node.step.z), ray.idz, -ofz);
            const float t_near = fmaxf(fmaxf(tnx, tny), fmaxf(tnz, ray.tmin));
            const float t_far = fminf(fminf(tfx, tfy), fminf(tfz, ray.tmax)) * kGpuFarScale;
            if (t_near <= t_far) {
                const int i = 4 * word + byte;
                const unsigned meta = cwbvh_byte(node.meta[word], byte);
                const unsigned bit = (meta & 31u) ^ ((node.inner >> i) & 1u ? oct_inv : 0u);
                hits |= (meta >> 5) << bit;
            }
        }
    };
    four_slots(0);
    four_slots(1);
    return hits;
}

/// Closest (kGpuClosest), any (kGpuAny) or filtered (kGpuFiltered) hit with t in
/// (tmin, tmax), by the paper's traversal (Sec. 3.3, without its warp-level postponing of
/// triangles): a node group holds the children of one node still to visit; the nearest-
/// looking one (by octant) is opened, the rest of the group pushed, and the triangles of the
/// opened node's leaf children are tested at once. Returns whether a hit was found
/// (accepted) and, for closest and filtered queries, writes it to `out`.
template <int kQuery, class Filter>
LUCENT_HD inline bool gpu_cwbvh_trace(const GpuCwbvhView& bvh, float3 origin, float3 dir,
                                      float tmin, float tmax, GpuHit& out, Filter& filter,
                                      GpuCwbvhStack& stack) {
    GpuCwbvhRay ray;
    ray.start(origin, dir, tmin, tmax);
    const WatertightRay wt = make_watertight_ray(origin, dir);
    const unsigned oct_inv = 7u - ray.octant();
    int hit_index = -1;
    float hit_u = 0.0f, hit_v = 0.0f;
    int sp = 0;
    // The root as a group of one: node 0, a node child in slot 0.
    unsigned group_base = 0, group_inner = 1u, group_nodes = 1u << oct_inv;
    for (;;) {
        unsigned triangle_base = 0, triangles = 0;
        if (group_nodes != 0u) {
            const unsigned bit = cwbvh_highest_bit(group_nodes);
            group_nodes &= ~(1u << bit);
            const unsigned slot = bit ^ oct_inv;
            const unsigned index =
                group_base + (unsigned)cwbvh_popc(group_inner & ((1u << slot) - 1u));
            if (group_nodes != 0u) {
                stack.base[sp] = group_base;
                stack.bits[sp++] = group_inner << 8 | group_nodes;
            }
            const GpuCwbvhNode node = GpuCwbvhNode::load(bvh.nodes, index);
            const unsigned hits = cwbvh_intersect_children(node, ray, oct_inv);
            group_base = node.child_base;
            group_inner = node.inner;
            group_nodes = hits >> kCwbvhInnerBit;
            triangle_base = node.triangle_base;
            triangles = hits & ((1u << kCwbvhInnerBit) - 1u);
        }
        while (triangles != 0u) {
            const unsigned i = triangle_base + cwbvh_lowest_bit(triangles);
            triangles &= triangles - 1u;
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
        if (group_nodes == 0u) {
            if (sp == 0) break;
            --sp;
            group_base = stack.base[sp];
            group_inner = stack.bits[sp] >> 8;
            group_nodes = stack.bits[sp] & 0xffu;
        }
    }
    if (hit_index < 0) return false;
    out.t = ray.tmax;
    out.u = hit_u;
    out.v = hit_v;
    out.prim = bvh.triangle_ids[hit_index];
    return true;
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

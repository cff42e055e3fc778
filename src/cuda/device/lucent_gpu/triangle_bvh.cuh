// GPU layout of a triangle BVH and its single-ray traversal, after Aila and Laine 2009,
// "Understanding the efficiency of ray traversal on GPUs" (HPG 2009), and its Kepler
// addendum (Aila, Laine and Karras 2012, NVIDIA Technical Report NVR-2012-02):
//
//  - a binary BVH whose inner node holds the boxes of BOTH children, so one node fetch
//    (64 bytes, four float4) tests two boxes and picks the nearer child;
//  - triangles copied into leaf order, three float4 each, so a leaf is one contiguous run;
//  - a "while-while" loop: traverse inner nodes until every lane of the warp has found a
//    leaf, then intersect leaves ("speculative traversal": a lane that found its first
//    leaf postpones it and keeps descending, Sec. 4 of the paper);
//  - an optional "dynamic fetch" exit (Kepler addendum): a persistent kernel can leave the
//    loop when too few lanes are still busy and hand the finished lanes new rays.
//
// The triangle test is the watertight one of the CPU backend
// (lucent/device/triangle_intersect.h), so the GPU finds the same hits as TriangleAccel, bit
// for bit. The box test is the CPU's too: plane * (1/d) - o/d in one FMA, o/d widened by a
// bound on its rounding, the far distance scaled up by 1 + 2^-21 (Ize 2013, "Robust BVH ray
// traversal"): boxes are only ever entered too often, never missed.
//
// The file compiles with g++ (host: the layout constants, and the same traversal run on
// the CPU to check the layout: every layout has a CPU traversal checked against brute force) and with NVRTC.
#pragma once

#include "lucent/device/platform.h"
#include "lucent/device/triangle_intersect.h"
#include "lucent/device/vector_math.h"

namespace lucent::gpu {

// ---- layout -------------------------------------------------------------------------
//
// Node n occupies nodes[4n .. 4n + 3]:
//   [4n + 0] = (c0.lo.x, c0.hi.x, c0.lo.y, c0.hi.y)
//   [4n + 1] = (c1.lo.x, c1.hi.x, c1.lo.y, c1.hi.y)
//   [4n + 2] = (c0.lo.z, c0.hi.z, c1.lo.z, c1.hi.z)
//   [4n + 3] = (child0, child1, 0, 0) as int bits
// A child reference >= 0 is an inner node, given as its float4 offset (4 * index). A
// negative one is a leaf: ~(first | (count - 1) << 28), i.e. `count` (1..8) triangles at
// triangles[3 * first ...]. Node 0 is the root and is always an inner node (a one-leaf
// tree gets a root whose second child is an empty box).
// Triangle i occupies triangles[3i .. 3i + 2] = (v0, 0), (v1, 0), (v2, 0), and
// triangle_ids[i] is its index in the input order.

constexpr int kGpuNodeFloat4s = 4;
constexpr int kGpuTriangleFloat4s = 3;
constexpr int kGpuLeafCountShift = 28;
constexpr unsigned kGpuLeafFirstMask = (1u << kGpuLeafCountShift) - 1u;
constexpr int kGpuMaxLeafSize = 8;
constexpr int kGpuStackSize = 64;                   // entries; the CPU builder caps depth at 60
constexpr int kGpuEntrypointSentinel = 0x76543210;  // bottom of the stack (Aila-Laine)
// The far distance is scaled by 1 + 2^-21 (Ize 2013): a near distance is at most (1 + u)^2
// times the true one and a far one at least (1 - u)^3 times it before this scale (1/d, the
// FMA, the multiply by the scale; u = 2^-24), so the test needs 1 + 5u; TriangleAccel takes
// the same margin (src/accel/triangle_traverse.cpp). 1 + 4u, used before, was a hair short.
constexpr float kGpuFarScale = 1.0f + 0x1p-21f;
constexpr float kGpuMaxInverse = 1e20f;      // |1/d| at most
constexpr float kGpuMaxOverInverse = 1e37f;  // |o/d| at most

/// Dynamic fetch (Kepler addendum): a persistent kernel leaves the traversal loop when
/// fewer lanes than this are still traversing, to refill the finished ones.
#ifndef LUCENT_GPU_DYNAMIC_FETCH_THRESHOLD
#define LUCENT_GPU_DYNAMIC_FETCH_THRESHOLD 20
#endif

LUCENT_HD inline int gpu_make_leaf(unsigned first, unsigned count) {
    return (int)~(first | ((count - 1u) << kGpuLeafCountShift));
}
LUCENT_HD inline unsigned gpu_leaf_first(int leaf) {
    return ((unsigned)~leaf) & kGpuLeafFirstMask;
}
LUCENT_HD inline unsigned gpu_leaf_count(int leaf) {
    return (((unsigned)~leaf) >> kGpuLeafCountShift) + 1u;
}

/// A hit: distance, barycentrics of vertices 1 and 2, triangle index in the input order.
struct GpuHit {
    float t, u, v;
    unsigned prim;
};

/// Device pointers of one uploaded GpuTriangleBvh (same layout on host and device).
struct GpuTriangleBvhView {
    const float4* nodes;
    const float4* triangles;
    const unsigned* triangle_ids;
};

/// What a filter (any-hit program) says about a candidate hit.
enum GpuFilterDecision : int { kGpuIgnore = 0, kGpuAccept = 1, kGpuAcceptAndStop = 2 };

enum GpuQuery : int { kGpuClosest = 0, kGpuAny = 1, kGpuFiltered = 2 };

// ---- loads and warp votes that also compile on the host -----------------------------

LUCENT_HD inline float4 gpu_load(const float4* p) {
#if LUCENT_GPU_CODE
    return __ldg(p);  // read-only data path (the texture fetches of the paper)
#else
    return *p;
#endif
}

LUCENT_HD inline int gpu_float_as_int(float f) {
#if LUCENT_GPU_CODE
    return __float_as_int(f);
#else
    return __builtin_bit_cast(int, f);
#endif
}

/// True when `p` holds on any lane of the converged warp (the host runs one lane).
LUCENT_HD inline bool gpu_warp_any(bool p) {
#if LUCENT_GPU_CODE
    return __any_sync(__activemask(), p);
#else
    return p;
#endif
}

/// Lanes still executing here (1 on the host).
LUCENT_HD inline int gpu_active_lanes() {
#if LUCENT_GPU_CODE
    return __popc(__activemask());
#else
    return 32;
#endif
}

/// Writes leaf-order triangle i (three float4 at tris + 3i) from its vertices: what both
/// GPU builders and the refit store.
LUCENT_HD inline void gpu_store_triangle(float4* tris, unsigned i, float3 a, float3 b, float3 c) {
    tris[3 * i + 0] = make_float4(a.x, a.y, a.z, 0.0f);
    tris[3 * i + 1] = make_float4(b.x, b.y, b.z, 0.0f);
    tris[3 * i + 2] = make_float4(c.x, c.y, c.z, 0.0f);
}

/// The watertight test of leaf-order triangle i (three float4 at tris + 3i) within
/// (tmin, tmax): the CPU's test, so the GPU finds the CPU's hits.
LUCENT_HD inline bool gpu_intersect_triangle(const float4* tris, unsigned i,
                                             const WatertightRay& wt, float tmin, float tmax,
                                             float& t, float& u, float& v) {
    const float4 a = gpu_load(tris + 3 * i + 0);
    const float4 b = gpu_load(tris + 3 * i + 1);
    const float4 c = gpu_load(tris + 3 * i + 2);
    return intersect_triangle_watertight(wt, make_float3(a.x, a.y, a.z), make_float3(b.x, b.y, b.z),
                                         make_float3(c.x, c.y, c.z), tmin, tmax, t, u, v);
}

struct GpuNoFilter {
    LUCENT_HD int operator()(const GpuHit&) const { return kGpuAccept; }
    /// With kDynamicFetch, run() returns once fewer lanes than this are traversing.
    LUCENT_HD int yield_below() const { return LUCENT_GPU_DYNAMIC_FETCH_THRESHOLD; }
};

// ---- traversal ---------------------------------------------------------------------

/// The traversal stack of one ray (local memory, cached in L1). It is kept apart from
/// GpuBvhTraversal: an array indexed at run time inside the struct would drag the whole
/// struct, ray included, into local memory.
struct GpuBvhStack {
    int entries[kGpuStackSize];
};

/// The state of one ray's traversal, all scalars so that it stays in registers. run() may
/// return before the ray is finished when kDynamicFetch is set; done() says whether it is.
struct GpuBvhTraversal {
    // The slab test in its fused form, as TriangleAccel's: t = plane * (1/d) - o/d, one FMA
    // per plane. o/d is rounded, so the plane that may be the nearer one subtracts o/d + err
    // and the farther one o/d - err (err bounds that rounding): boxes only grow.
    float idx, idy, idz;     // 1 / direction, clamped to +-kGpuMaxInverse
    float olox, oloy, oloz;  // o/d -+ err for the lo planes
    float ohix, ohiy, ohiz;  // o/d -+ err for the hi planes
    float tmin, tmax;        // tmax shrinks to the closest accepted hit
    WatertightRay wt;
    int node;  // inner node offset, a leaf (< 0), or the sentinel when done
    int leaf;  // a postponed leaf (< 0), or >= 0 for none
    int sp;
    int hit_index;  // leaf-order index of the closest accepted hit, -1 for none
    float hit_u, hit_v;

    /// Clamped 1/d, and the o/d terms of the lo and hi planes of one axis.
    LUCENT_HD static void axis_terms(float o, float d, float& id, float& olo, float& ohi) {
        // 1/+-0 is +-inf: clamped so that o/d stays finite wherever the origin is.
        const float limit = fminf(kGpuMaxInverse, kGpuMaxOverInverse / fmaxf(fabsf(o), 1.0f));
        id = fminf(fmaxf(1.0f / d, -limit), limit);
        const float od = o * id;
        const float err = fabsf(od) * 0x1p-21f;  // > the rounding of o * id
        // A lo plane is the near one when the direction is positive.
        olo = id >= 0.0f ? od + err : od - err;
        ohi = id >= 0.0f ? od - err : od + err;
    }

    LUCENT_HD void start(float3 origin, float3 dir, float t0, float t1, GpuBvhStack& stack) {
        axis_terms(origin.x, dir.x, idx, olox, ohix);
        axis_terms(origin.y, dir.y, idy, oloy, ohiy);
        axis_terms(origin.z, dir.z, idz, oloz, ohiz);
        tmin = t0;
        tmax = t1;
        wt = make_watertight_ray(origin, dir);
        node = 0;
        leaf = 0;
        sp = 0;
        stack.entries[0] = kGpuEntrypointSentinel;
        hit_index = -1;
        hit_u = hit_v = 0.0f;
    }
    LUCENT_HD void finish() {
        node = kGpuEntrypointSentinel;
        leaf = 0;
    }
    LUCENT_HD bool done() const { return node == kGpuEntrypointSentinel; }
    LUCENT_HD bool hit() const { return hit_index >= 0; }

    /// Near and far distances of one child box: the CPU's slab test (near planes chosen by
    /// the sign of the direction, far distance * kGpuFarScale). An empty box (lo > hi) is
    /// never entered. `r` is any state with this struct's idx .. ohiz, tmin and tmax.
    template <class Ray>
    LUCENT_HD static void slab(float lox, float hix, float loy, float hiy, float loz, float hiz,
                               const Ray& r, float& t_near, float& t_far) {
        const float tlx = fmaf(lox, r.idx, -r.olox), thx = fmaf(hix, r.idx, -r.ohix);
        const float tly = fmaf(loy, r.idy, -r.oloy), thy = fmaf(hiy, r.idy, -r.ohiy);
        const float tlz = fmaf(loz, r.idz, -r.oloz), thz = fmaf(hiz, r.idz, -r.ohiz);
        const bool px = r.idx >= 0.0f, py = r.idy >= 0.0f, pz = r.idz >= 0.0f;
        const float nx = px ? tlx : thx, fx = px ? thx : tlx;
        const float ny = py ? tly : thy, fy = py ? thy : tly;
        const float nz = pz ? tlz : thz, fz = pz ? thz : tlz;
        t_near = fmaxf(fmaxf(nx, ny), fmaxf(nz, r.tmin));
        t_far = fminf(fminf(fx, fy), fminf(fz, r.tmax)) * kGpuFarScale;
    }

    /// Traverses until done, or (kDynamicFetch) until fewer lanes of the warp than
    /// filter.yield_below() are busy.
    template <int kQuery, bool kDynamicFetch, class Filter>
    LUCENT_HD void run(const GpuTriangleBvhView& bvh, Filter& filter, GpuBvhStack& stack_memory) {
        int* const stack = stack_memory.entries;
        const float4* __restrict__ nodes = bvh.nodes;
        const float4* __restrict__ tris = bvh.triangles;
        while (node != kGpuEntrypointSentinel) {
            // Inner nodes until every lane has found a leaf (or finished). Inner node
            // offsets are below the sentinel; leaves (negative) are huge as unsigned.
            while ((unsigned)node < (unsigned)kGpuEntrypointSentinel) {
                const float4 n0 = gpu_load(nodes + node + 0);
                const float4 n1 = gpu_load(nodes + node + 1);
                const float4 nz = gpu_load(nodes + node + 2);
                const float4 nc = gpu_load(nodes + node + 3);
                float c0_near, c0_far, c1_near, c1_far;
                slab(n0.x, n0.y, n0.z, n0.w, nz.x, nz.y, *this, c0_near, c0_far);
                slab(n1.x, n1.y, n1.z, n1.w, nz.z, nz.w, *this, c1_near, c1_far);
                const bool hit0 = c0_near <= c0_far;
                const bool hit1 = c1_near <= c1_far;
                int child0 = gpu_float_as_int(nc.x);
                int child1 = gpu_float_as_int(nc.y);
                if (!hit0 && !hit1) {
                    node = stack[sp--];
                } else {
                    node = hit0 ? child0 : child1;
                    if (hit0 && hit1) {
                        // Both: go to the nearer, push the farther.
                        if (c1_near < c0_near) {
                            const int tmp = node;
                            node = child1;
                            child1 = tmp;
                        }
                        stack[++sp] = child1;
                    }
                }
                // First leaf: postpone it and keep descending (speculative traversal).
                if (node < 0 && leaf >= 0) {
                    leaf = node;
                    node = stack[sp--];
                }
                // Every lane has a leaf (or is done): go and intersect.
                if (!gpu_warp_any(leaf >= 0)) break;
            }

            // Postponed leaves, then the one `node` may hold.
            while (leaf < 0) {
                const unsigned first = gpu_leaf_first(leaf);
                const unsigned end = first + gpu_leaf_count(leaf);
                for (unsigned i = first; i < end; ++i) {
                    float t, u, v;
                    if (!gpu_intersect_triangle(tris, i, wt, tmin, tmax, t, u, v)) continue;
                    if constexpr (kQuery == kGpuFiltered) {
                        GpuHit candidate;
                        candidate.t = t;
                        candidate.u = u;
                        candidate.v = v;
                        candidate.prim = bvh.triangle_ids[i];
                        const int decision = filter(candidate);
                        if (decision == kGpuIgnore) continue;
                        tmax = t;
                        hit_index = (int)i;
                        hit_u = u;
                        hit_v = v;
                        if (decision == kGpuAcceptAndStop) {
                            finish();
                            return;
                        }
                    } else {
                        tmax = t;
                        hit_index = (int)i;
                        hit_u = u;
                        hit_v = v;
                        if constexpr (kQuery == kGpuAny) {
                            finish();
                            return;
                        }
                    }
                }
                // Another leaf was postponed in `node`: take it too.
                leaf = node;
                if (node < 0) node = stack[sp--];
            }

            if constexpr (kDynamicFetch) {
                if (gpu_active_lanes() < filter.yield_below()) return;
            }
        }
    }

    /// The result of a finished closest / filtered query.
    LUCENT_HD bool result(const GpuTriangleBvhView& bvh, GpuHit& out) const {
        if (hit_index < 0) return false;
        out.t = tmax;
        out.u = hit_u;
        out.v = hit_v;
        out.prim = bvh.triangle_ids[hit_index];
        return true;
    }
};

/// Closest hit with t in (tmin, tmax).
LUCENT_HD inline bool gpu_bvh_closest(const GpuTriangleBvhView& bvh, float3 origin, float3 dir,
                                      float tmin, float tmax, GpuHit& hit) {
    GpuBvhStack stack;
    GpuBvhTraversal tr;
    tr.start(origin, dir, tmin, tmax, stack);
    GpuNoFilter none;
    tr.run<kGpuClosest, false>(bvh, none, stack);
    return tr.result(bvh, hit);
}

/// True when any triangle is hit with t in (tmin, tmax); stops at the first.
LUCENT_HD inline bool gpu_bvh_occluded(const GpuTriangleBvhView& bvh, float3 origin, float3 dir,
                                       float tmin, float tmax) {
    GpuBvhStack stack;
    GpuBvhTraversal tr;
    tr.start(origin, dir, tmin, tmax, stack);
    GpuNoFilter none;
    tr.run<kGpuAny, false>(bvh, none, stack);
    return tr.hit();
}

/// Conservative occlusion by the leaf boxes (Occlusion::kLeafBoxes, TriangleAccel's
/// occluded_leaf_boxes): true when the ray passes wholly through a leaf's box within
/// (tmin, tmax). Inner nodes only: a leaf child is either the answer or skipped, so no
/// triangle is loaded. Plain stack order, without the speculative leaf postponing, which
/// has no leaves to postpone here.
LUCENT_HD inline bool gpu_bvh_occluded_leaf_boxes(const GpuTriangleBvhView& bvh, float3 origin,
                                                  float3 dir, float tmin, float tmax) {
    GpuBvhStack stack_memory;
    GpuBvhTraversal tr;
    tr.start(origin, dir, tmin, tmax, stack_memory);
    int* const stack = stack_memory.entries;
    const float4* __restrict__ nodes = bvh.nodes;
    int node = 0, sp = 0;
    while (node != kGpuEntrypointSentinel) {
        const float4 n0 = gpu_load(nodes + node + 0);
        const float4 n1 = gpu_load(nodes + node + 1);
        const float4 nz = gpu_load(nodes + node + 2);
        const float4 nc = gpu_load(nodes + node + 3);
        float c0_near, c0_far, c1_near, c1_far;
        GpuBvhTraversal::slab(n0.x, n0.y, n0.z, n0.w, nz.x, nz.y, tr, c0_near, c0_far);
        GpuBvhTraversal::slab(n1.x, n1.y, n1.z, n1.w, nz.z, nz.w, tr, c1_near, c1_far);
        int child0 = gpu_float_as_int(nc.x);
        int child1 = gpu_float_as_int(nc.y);
        bool hit0 = c0_near <= c0_far;
        bool hit1 = c1_near <= c1_far;
        // A leaf entered after tmin and left before tmax blocks the ray (slab() clamps near
        // to tmin and far to tmax * kGpuFarScale, so strict comparisons mean "within").
        if (hit0 && child0 < 0) {
            if (c0_near > tmin && c0_far < tmax) return true;
            hit0 = false;
        }
        if (hit1 && child1 < 0) {
            if (c1_near > tmin && c1_far < tmax) return true;
            hit1 = false;
        }
        if (!hit0 && !hit1) {
            node = stack[sp--];
        } else {
            node = hit0 ? child0 : child1;
            if (hit0 && hit1) stack[++sp] = child1;
        }
    }
    return false;
}

/// Closest hit where each candidate nearer than the closest accepted one is first offered
/// to filter(const GpuHit&) -> int: kGpuIgnore (0), kGpuAccept (1) or kGpuAcceptAndStop
/// (2). Candidates come in traversal order, not sorted. `hit` gets the closest accepted.
template <class Filter>
LUCENT_HD inline bool gpu_bvh_filtered(const GpuTriangleBvhView& bvh, float3 origin, float3 dir,
                                       float tmin, float tmax, GpuHit& hit, Filter&& filter) {
    GpuBvhStack stack;
    GpuBvhTraversal tr;
    tr.start(origin, dir, tmin, tmax, stack);
    tr.run<kGpuFiltered, false>(bvh, filter, stack);
    return tr.result(bvh, hit);
}

}  // namespace lucent::gpu

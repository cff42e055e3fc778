// The GPU binned-SAH triangle BVH builder: the host builder's algorithm (src/accel/bvh.cpp,
// Wald 2007, "On fast construction of SAH-based bounding volume hierarchies": 32 bins per
// axis on the centroids, fewer for small nodes, the SAH leaf test, the median split near the
// depth limit) run breadth-first on the GPU, one level of the tree at a time, as in
// Garanzha, Pantaleoni and McAllister 2011 ("Simpler and faster HLBVH with work queues",
// their binned-SAH top levels) but for every level. It makes the host's tree (the same
// splits, up to the order of triangles inside a leaf), so it traces as fast, and writes the
// layout of triangle_bvh.cuh directly. H-PLOC (bvh_build.cuh) builds faster trees that trace
// at 0.85-0.99x of this one (docs/performance.md).
//
// The passes, one kernel each; 2 to 4 run once per level (gpu_bvh_builder.cpp launches them):
//  1. lucent_sah_init:      each triangle's box; the root's box and centroid box (atomics).
//  2. lucent_sah_bin:       each triangle still in a task of this level adds its box to its
//     task's bins (three axes, ordered-integer atomics).
//  3. lucent_sah_split:     each task of the level sweeps its bins, and becomes a leaf or two
//     children (a node pair; tasks of the next level, or leaves at once for one triangle).
//  4. lucent_sah_partition: each triangle goes to its child's task, growing its boxes, or,
//     in a leaf, takes its place in the leaf order.
//  5. lucent_sah_count:     bottom-up, the inner nodes and the SAH cost of every subtree.
//  6. lucent_sah_emit:      each inner node finds its depth-first place (child 0 right after
//     its parent, as the host's layout) and writes its 64-byte node; lucent_sah_triangles
//     copies the triangles into leaf order.
//
// Every kernel body is a plain function of (params, thread index) built for the host too:
// tests run the whole build on the CPU, a thread at a time (gpu_sah_build_emulated).
#pragma once

#include "lucent/device/platform.h"
#include "lucent/device/types.h"
#include "lucent_gpu/triangle_bvh.cuh"

#if !LUCENT_GPU_CODE
#include <atomic>
#include <bit>
#include <cstring>
#endif

namespace lucent::gpu {

constexpr unsigned kSahInvalid = 0xffffffffu;
constexpr int kSahBins = 32;            // the host's BuildOptions::bins
constexpr unsigned kSahMaxDepth = 60;   // the host's kMaxDepth: deeper gets median splits
constexpr int kSahBinWords = 7;         // count, lo xyz, hi xyz (ordered integers)
constexpr unsigned kSahLevels = 64;     // kSahMaxDepth + the leaves, with room
constexpr float kSahEmpty = 3.0e38f;    // the lo of an empty box (its hi is -kSahEmpty)

/// Words of GpuSahBuildParams::counters.
enum GpuSahCounter : int {
    kSahNextNode = 0,    // nodes are handed out in pairs from 1 (0 is the root)
    kSahTaskCount = 1,   // 2 words: tasks of the even and the odd levels
    kSahPoolUsed = 3,    // 2 words: bin words used by the even and the odd levels
    kSahBadIndex = 5,    // the first triangle with a vertex out of range, or kSahInvalid
    kSahDepth = 6,       // inner levels of the emitted tree
    kSahCost = 7,        // SAH cost of the tree (as the host's Bvh::sah_cost), float bits
    kSahInner = 8,       // inner nodes emitted
    kSahFault = 9,       // 0, or the first GpuSahFault
    kSahCounterCount = 10
};

enum GpuSahFault : unsigned {
    kSahFaultNone = 0,
    kSahFaultPool = 1,      // the bins of a level outgrew their pool
    kSahFaultNodes = 2,     // more than 2N - 1 nodes
    kSahFaultDeepTree = 3,  // a walk to the root longer than the traversal stack
};

/// One node of the level being built: the range [begin, begin + count) of the leaf order
/// its triangles will take, its boxes (grown by the level above) and its decision.
struct GpuSahTask {
    unsigned node, begin, count, depth;
    int box[6];   // lo xyz, hi xyz as ordered integers
    int cbox[6];  // the box of the doubled centroids (lo + hi), likewise
    unsigned bins;        // first word of its bins in the level's pool
    unsigned bin_count;   // bins per axis (min(32, count + 4), as the host)
    unsigned decision;    // kSahDecideLeaf, kSahDecideMedian, or axis << 8 | bin
    unsigned left_count;  // triangles of child 0
    unsigned child_task[2];  // task of each child in the next level, or kSahInvalid (a leaf)
    unsigned child_node;     // node of child 0 (child 1 is the next one)
    unsigned fill;           // triangles placed so far (a leaf) or sent left (a median split)
};

constexpr unsigned kSahDecideLeaf = 0xffffffffu;
constexpr unsigned kSahDecideMedian = 0xfffffffeu;

/// Everything the kernels read and write (device pointers; host pointers on the CPU).
struct GpuSahBuildParams {
    const float3* positions;
    const uint3* indices;  // null: triangle i is positions[3i .. 3i + 2]
    unsigned vertex_count, triangle_count;
    unsigned max_leaf_size;
    float traversal_cost, intersection_cost;
    unsigned level;        // the level the per-level kernels work on
    unsigned pool_words;   // capacity of each bin pool
    // scratch, N = triangle_count
    float4* prim_lo;       // N triangle boxes
    float4* prim_hi;
    unsigned* prim_task;   // N: its task in the current level; kSahInvalid once placed
    unsigned* order;       // N: triangles in leaf order
    GpuSahTask* tasks[2];  // N / 2 + 1 each: even and odd levels
    unsigned* pool[2];     // bins of the tasks of even and odd levels
    float4* node_lo;       // 2N - 1 nodes: xyz, w = SAH cost of the subtree
    float4* node_hi;       // xyz, w unused
    uint2* node_range;     // inner: (child 0, 0); leaf: (first, count)
    unsigned* node_parent;
    unsigned* node_inner;     // inner nodes of the subtree
    unsigned* node_arrivals;  // children counted so far (the bottom-up pass)
    unsigned* counters;       // GpuSahCounter
    // the layout (triangle_bvh.cuh)
    float4* out_nodes;
    float4* out_triangles;
    unsigned* out_triangle_ids;
    unsigned* out_parents;  // per emitted node: parent << 1 | slot, kSahInvalid at the root
};

// ---- helpers for both compilers ------------------------------------------------------------

LUCENT_HD inline int sah_ordered(float f) {  // monotonic float -> int, for atomicMin/Max
#if LUCENT_GPU_CODE
    const int i = __float_as_int(f);
#else
    const int i = std::bit_cast<int>(f);
#endif
    return i >= 0 ? i : i ^ 0x7fffffff;
}
LUCENT_HD inline float sah_from_ordered(int i) {
    const int b = i >= 0 ? i : i ^ 0x7fffffff;
#if LUCENT_GPU_CODE
    return __int_as_float(b);
#else
    return std::bit_cast<float>(b);
#endif
}
LUCENT_HD inline unsigned sah_float_bits(float f) {
#if LUCENT_GPU_CODE
    return __float_as_uint(f);
#else
    return std::bit_cast<unsigned>(f);
#endif
}
LUCENT_HD inline unsigned sah_atomic_add(unsigned* a, unsigned v) {
#if LUCENT_GPU_CODE
    return atomicAdd(a, v);
#else
    return std::atomic_ref<unsigned>(*a).fetch_add(v);
#endif
}
LUCENT_HD inline void sah_atomic_min(int* a, int v) {
#if LUCENT_GPU_CODE
    atomicMin(a, v);
#else
    std::atomic_ref<int> r(*a);
    int old = r.load();
    while (v < old && !r.compare_exchange_weak(old, v)) {
    }
#endif
}
LUCENT_HD inline void sah_atomic_max(int* a, int v) {
#if LUCENT_GPU_CODE
    atomicMax(a, v);
#else
    std::atomic_ref<int> r(*a);
    int old = r.load();
    while (v > old && !r.compare_exchange_weak(old, v)) {
    }
#endif
}
LUCENT_HD inline void sah_atomic_first(unsigned* a, unsigned v) {  // keeps the first fault
#if LUCENT_GPU_CODE
    atomicCAS(a, 0u, v);
#else
    unsigned expected = 0;
    std::atomic_ref<unsigned>(*a).compare_exchange_strong(expected, v);
#endif
}
LUCENT_HD inline void sah_atomic_min_u(unsigned* a, unsigned v) {
#if LUCENT_GPU_CODE
    atomicMin(a, v);
#else
    std::atomic_ref<unsigned> r(*a);
    unsigned old = r.load();
    while (v < old && !r.compare_exchange_weak(old, v)) {
    }
#endif
}
LUCENT_HD inline void sah_atomic_max_u(unsigned* a, unsigned v) {
#if LUCENT_GPU_CODE
    atomicMax(a, v);
#else
    std::atomic_ref<unsigned> r(*a);
    unsigned old = r.load();
    while (v > old && !r.compare_exchange_weak(old, v)) {
    }
#endif
}
/// Makes this thread's stores visible before its next atomic (the bottom-up pass).
LUCENT_HD inline void sah_fence() {
#if LUCENT_GPU_CODE
    __threadfence();
#else
    std::atomic_thread_fence(std::memory_order_seq_cst);
#endif
}

// Products and sums rounded one at a time, as the host (x86-64-v2 has no FMA): the same
// inputs pick the same split on both.
LUCENT_HD inline float sah_mul(float a, float b) {
#if LUCENT_GPU_CODE
    return __fmul_rn(a, b);
#else
    return a * b;
#endif
}
LUCENT_HD inline float sah_add(float a, float b) {
#if LUCENT_GPU_CODE
    return __fadd_rn(a, b);
#else
    return a + b;
#endif
}

/// Half the surface area; 0 for an empty box (the host's Box::half_area).
LUCENT_HD inline float sah_half_area(float3 lo, float3 hi) {
    const float dx = hi.x - lo.x, dy = hi.y - lo.y, dz = hi.z - lo.z;
    if (!(dx >= 0.0f)) return 0.0f;
    return sah_add(sah_add(sah_mul(dx, dy), sah_mul(dy, dz)), sah_mul(dz, dx));
}

LUCENT_HD inline float sah_axis(float3 v, int k) {
    return k == 0 ? v.x : k == 1 ? v.y : v.z;
}

LUCENT_HD inline void sah_box_of(const int* ordered, float3& lo, float3& hi) {
    lo = make_float3(sah_from_ordered(ordered[0]), sah_from_ordered(ordered[1]),
                     sah_from_ordered(ordered[2]));
    hi = make_float3(sah_from_ordered(ordered[3]), sah_from_ordered(ordered[4]),
                     sah_from_ordered(ordered[5]));
}

LUCENT_HD inline void sah_clear_box(int* ordered) {
    for (int k = 0; k < 3; ++k) {
        ordered[k] = sah_ordered(kSahEmpty);
        ordered[3 + k] = sah_ordered(-kSahEmpty);
    }
}

LUCENT_HD inline void sah_grow_box(int* ordered, float3 lo, float3 hi) {
    sah_atomic_min(ordered + 0, sah_ordered(lo.x));
    sah_atomic_min(ordered + 1, sah_ordered(lo.y));
    sah_atomic_min(ordered + 2, sah_ordered(lo.z));
    sah_atomic_max(ordered + 3, sah_ordered(hi.x));
    sah_atomic_max(ordered + 4, sah_ordered(hi.y));
    sah_atomic_max(ordered + 5, sah_ordered(hi.z));
}

LUCENT_HD inline uint3 sah_triangle(const GpuSahBuildParams& p, unsigned t) {
    return p.indices ? p.indices[t] : make_uint3(3 * t, 3 * t + 1, 3 * t + 2);
}

LUCENT_HD inline float3 sah_xyz(float4 v) {
    return make_float3(v.x, v.y, v.z);
}

/// Scale of the bins along each axis of a task (the host's: bins * 0.99999 / extent of the
/// doubled centroids; 0 for a flat axis, which is not split).
LUCENT_HD inline float3 sah_bin_scale(const GpuSahTask& t) {
    float3 lo, hi;
    sah_box_of(t.cbox, lo, hi);
    const float bins = (float)t.bin_count;
    auto scale = [&](float extent) { return extent > 0.0f ? bins * 0.99999f / extent : 0.0f; };
    return make_float3(scale(hi.x - lo.x), scale(hi.y - lo.y), scale(hi.z - lo.z));
}

/// The host's bin_of: the bin of a triangle (box lo, hi) along axis k.
LUCENT_HD inline int sah_bin_of(float lo, float hi, float clo, float scale, unsigned bins) {
    const int b = (int)((lo + hi - clo) * scale);
    return b < 0 ? 0 : b > (int)bins - 1 ? (int)bins - 1 : b;
}

LUCENT_HD inline bool sah_force_median(const GpuSahTask& t, unsigned max_leaf) {
    const unsigned leaves = (t.count + max_leaf - 1) / max_leaf;
    unsigned levels_needed = 0;  // std::bit_width
    for (unsigned v = leaves; v; v >>= 1) ++levels_needed;
    return t.depth + levels_needed + 1 >= kSahMaxDepth;
}

// ---- 1: triangle boxes and the root ---------------------------------------------------------

LUCENT_HD inline void sah_init(const GpuSahBuildParams& p, unsigned i) {
    if (i >= p.triangle_count) return;
    const uint3 v = sah_triangle(p, i);
    float3 lo = make_float3(0.0f, 0.0f, 0.0f), hi = lo;
    if (v.x < p.vertex_count && v.y < p.vertex_count && v.z < p.vertex_count) {
        const float3 a = p.positions[v.x], b = p.positions[v.y], c = p.positions[v.z];
        lo = fminf(a, fminf(b, c));
        hi = fmaxf(a, fmaxf(b, c));
    } else {
        sah_atomic_min_u(&p.counters[kSahBadIndex], i);
    }
    p.prim_lo[i] = make_float4(lo.x, lo.y, lo.z, 0.0f);
    p.prim_hi[i] = make_float4(hi.x, hi.y, hi.z, 0.0f);
    p.prim_task[i] = 0;
    p.node_arrivals[i] = 0;  // 2N - 1 nodes: two each (the bottom-up pass counts on them)
    if (p.triangle_count + i < 2 * p.triangle_count - 1) p.node_arrivals[p.triangle_count + i] = 0;
    GpuSahTask& root = p.tasks[0][0];
    sah_grow_box(root.box, lo, hi);
    const float3 c = lo + hi;  // doubled centroid, as the host keeps them
    sah_grow_box(root.cbox, c, c);
}

// ---- 2: bins ----------------------------------------------------------------------------------

LUCENT_HD inline void sah_bin(const GpuSahBuildParams& p, unsigned i) {
    const unsigned parity = p.level & 1u;
    if (i == 0) {  // the next level's counts: its tasks are made by this level's split
        p.counters[kSahTaskCount + (parity ^ 1u)] = 0;
        p.counters[kSahPoolUsed + (parity ^ 1u)] = 0;
    }
    if (i >= p.triangle_count) return;
    const unsigned ti = p.prim_task[i];
    if (ti == kSahInvalid) return;
    const GpuSahTask& t = p.tasks[parity][ti];
    if (t.bin_count == 0) return;  // a median split: no bins
    const float3 lo = sah_xyz(p.prim_lo[i]), hi = sah_xyz(p.prim_hi[i]);
    float3 clo, chi;
    sah_box_of(t.cbox, clo, chi);
    const float3 scale = sah_bin_scale(t);
    unsigned* bins = p.pool[parity] + t.bins;
    for (int k = 0; k < 3; ++k) {
        const int b = sah_bin_of(sah_axis(lo, k), sah_axis(hi, k), sah_axis(clo, k),
                                 sah_axis(scale, k), t.bin_count);
        unsigned* bin = bins + (k * t.bin_count + (unsigned)b) * kSahBinWords;
        sah_atomic_add(bin, 1u);
        sah_grow_box(reinterpret_cast<int*>(bin + 1), lo, hi);
    }
}

// ---- 3: split or leaf -------------------------------------------------------------------------

/// Makes a task for the level of `parity` over [begin, begin + count) of the leaf order,
/// with room for its bins (none when it will be split at the median).
LUCENT_HD inline unsigned sah_new_task(const GpuSahBuildParams& p, unsigned parity, unsigned node,
                                       unsigned begin, unsigned count, unsigned depth) {
    const unsigned ti = sah_atomic_add(&p.counters[kSahTaskCount + parity], 1u);
    GpuSahTask& t = p.tasks[parity][ti];
    t.node = node, t.begin = begin, t.count = count, t.depth = depth;
    sah_clear_box(t.box);
    sah_clear_box(t.cbox);
    t.fill = 0;
    t.bin_count = 0;
    t.bins = 0;
    if (sah_force_median(t, p.max_leaf_size)) return ti;
    const unsigned bins = count + 4 < (unsigned)kSahBins ? count + 4 : (unsigned)kSahBins;
    const unsigned words = 3 * bins * kSahBinWords;
    const unsigned at = sah_atomic_add(&p.counters[kSahPoolUsed + parity], words);
    if (at + words > p.pool_words) {
        sah_atomic_first(&p.counters[kSahFault], kSahFaultPool);
        return ti;  // split at the median; the build fails anyway
    }
    t.bin_count = bins;
    t.bins = at;
    unsigned* w = p.pool[parity] + at;
    for (unsigned b = 0; b < 3 * bins; ++b, w += kSahBinWords) {
        w[0] = 0;
        sah_clear_box(reinterpret_cast<int*>(w + 1));
    }
    return ti;
}

/// The task of the next level for a child of `count` triangles over [begin, ...), or
/// kSahInvalid for a single triangle, which is a leaf at once.
LUCENT_HD inline unsigned sah_child_task(const GpuSahBuildParams& p, unsigned node, unsigned begin,
                                         unsigned count, unsigned depth) {
    p.node_range[node] = make_uint2(begin, count);  // a leaf unless its task splits it
    if (count <= 1) return kSahInvalid;
    return sah_new_task(p, (p.level + 1) & 1u, node, begin, count, depth);
}

/// One thread: the counters, and the root as the one task of level 0.
LUCENT_HD inline void sah_reset(const GpuSahBuildParams& p, unsigned i) {
    if (i != 0) return;
    for (int c = 0; c < kSahCounterCount; ++c) p.counters[c] = 0;
    p.counters[kSahNextNode] = 1;
    p.counters[kSahBadIndex] = kSahInvalid;
    p.node_parent[0] = kSahInvalid;
    p.node_range[0] = make_uint2(0u, p.triangle_count);
    sah_new_task(p, 0u, 0u, 0u, p.triangle_count, 0u);
}

LUCENT_HD inline void sah_split(const GpuSahBuildParams& p, unsigned ti) {
    const unsigned parity = p.level & 1u;
    if (ti >= p.counters[kSahTaskCount + parity]) return;
    GpuSahTask& t = p.tasks[parity][ti];
    float3 lo, hi;
    sah_box_of(t.box, lo, hi);
    p.node_lo[t.node] = make_float4(lo.x, lo.y, lo.z, 0.0f);
    p.node_hi[t.node] = make_float4(hi.x, hi.y, hi.z, 0.0f);
    const unsigned n = t.count;

    // The host's sweep (bvh.cpp, Builder::build): per axis, right-to-left areas and counts,
    // then each plane's cost, the first strictly cheapest kept.
    int best_axis = -1, best_bin = 0;
    float best_cost = 3.402823e38f;
    unsigned best_left = 0;
    if (t.bin_count > 0) {
        const float3 scale = sah_bin_scale(t);
        const unsigned* bins = p.pool[parity] + t.bins;
        const unsigned nb = t.bin_count;
        for (int k = 0; k < 3; ++k) {
            if (sah_axis(scale, k) == 0.0f) continue;
            const unsigned* axis = bins + k * nb * kSahBinWords;
            float right_area[kSahBins];
            unsigned right_count[kSahBins];
            int acc[6];
            sah_clear_box(acc);
            unsigned cnt = 0;
            for (int b = (int)nb - 1; b > 0; --b) {
                const unsigned* bin = axis + b * kSahBinWords;
                const int* box = reinterpret_cast<const int*>(bin + 1);
                for (int c = 0; c < 3; ++c) {
                    acc[c] = box[c] < acc[c] ? box[c] : acc[c];
                    acc[3 + c] = box[3 + c] > acc[3 + c] ? box[3 + c] : acc[3 + c];
                }
                cnt += bin[0];
                float3 alo, ahi;
                sah_box_of(acc, alo, ahi);
                right_area[b] = sah_half_area(alo, ahi);
                right_count[b] = cnt;
            }
            int left[6];
            sah_clear_box(left);
            unsigned left_count = 0;
            for (int b = 1; b < (int)nb; ++b) {
                const unsigned* bin = axis + (b - 1) * kSahBinWords;
                const int* box = reinterpret_cast<const int*>(bin + 1);
                for (int c = 0; c < 3; ++c) {
                    left[c] = box[c] < left[c] ? box[c] : left[c];
                    left[3 + c] = box[3 + c] > left[3 + c] ? box[3 + c] : left[3 + c];
                }
                left_count += bin[0];
                if (left_count == 0 || right_count[b] == 0) continue;
                float3 llo, lhi;
                sah_box_of(left, llo, lhi);
                const float cost = sah_add(sah_mul(sah_half_area(llo, lhi), (float)left_count),
                                           sah_mul(right_area[b], (float)right_count[b]));
                if (cost < best_cost) {
                    best_cost = cost, best_axis = k, best_bin = b, best_left = left_count;
                }
            }
        }
    }
    const float area = sah_half_area(lo, hi);
    bool leaf = n <= 1;
    if (!leaf && best_axis >= 0 && n <= p.max_leaf_size) {
        // SAH termination: a leaf when testing its triangles is no dearer than a split.
        const float split =
            sah_add(p.traversal_cost, sah_mul(p.intersection_cost, best_cost) / area);
        leaf = !(area > 0.0f) || sah_mul(p.intersection_cost, (float)n) <= split;
    }
    if (!leaf && best_axis < 0 && n <= p.max_leaf_size) leaf = true;
    if (leaf) {
        t.decision = kSahDecideLeaf;
        p.node_range[t.node] = make_uint2(t.begin, n);
        return;
    }
    // All centroids coincide, or near the depth limit: half and half (the host's median).
    t.decision = best_axis >= 0 ? (unsigned)best_axis << 8 | (unsigned)best_bin : kSahDecideMedian;
    t.left_count = best_axis >= 0 ? best_left : n / 2;
    const unsigned c0 = sah_atomic_add(&p.counters[kSahNextNode], 2u);
    if (c0 + 2 > 2 * p.triangle_count - 1) {
        sah_atomic_first(&p.counters[kSahFault], kSahFaultNodes);
        t.decision = kSahDecideLeaf;  // keeps the partition in bounds; the build fails
        return;
    }
    t.child_node = c0;
    p.node_range[t.node] = make_uint2(c0, 0u);
    p.node_parent[c0] = t.node;
    p.node_parent[c0 + 1] = t.node;
    t.child_task[0] = sah_child_task(p, c0, t.begin, t.left_count, t.depth + 1);
    t.child_task[1] = sah_child_task(p, c0 + 1, t.begin + t.left_count, n - t.left_count,
                                     t.depth + 1);
}

// ---- 4: partition ---------------------------------------------------------------------------

LUCENT_HD inline void sah_partition(const GpuSahBuildParams& p, unsigned i) {
    if (i >= p.triangle_count) return;
    const unsigned ti = p.prim_task[i];
    if (ti == kSahInvalid) return;
    const unsigned parity = p.level & 1u;
    GpuSahTask& t = p.tasks[parity][ti];
    const float3 lo = sah_xyz(p.prim_lo[i]), hi = sah_xyz(p.prim_hi[i]);
    if (t.decision == kSahDecideLeaf) {
        p.order[t.begin + sah_atomic_add(&t.fill, 1u)] = i;
        p.prim_task[i] = kSahInvalid;
        return;
    }
    int side;
    if (t.decision == kSahDecideMedian) {
        side = sah_atomic_add(&t.fill, 1u) < t.left_count ? 0 : 1;
    } else {
        const int k = (int)(t.decision >> 8), split_bin = (int)(t.decision & 0xffu);
        float3 clo, chi;
        sah_box_of(t.cbox, clo, chi);
        const int b = sah_bin_of(sah_axis(lo, k), sah_axis(hi, k), sah_axis(clo, k),
                                 sah_axis(sah_bin_scale(t), k), t.bin_count);
        side = b < split_bin ? 0 : 1;
    }
    const unsigned child = t.child_task[side];
    if (child == kSahInvalid) {  // a one-triangle leaf
        const unsigned node = t.child_node + (unsigned)side;
        p.node_lo[node] = make_float4(lo.x, lo.y, lo.z, 0.0f);
        p.node_hi[node] = make_float4(hi.x, hi.y, hi.z, 0.0f);
        p.order[side == 0 ? t.begin : t.begin + t.left_count] = i;
        p.prim_task[i] = kSahInvalid;
        return;
    }
    GpuSahTask& c = p.tasks[parity ^ 1u][child];
    sah_grow_box(c.box, lo, hi);
    const float3 centroid = lo + hi;
    sah_grow_box(c.cbox, centroid, centroid);
    p.prim_task[i] = child;
}

// ---- 5: subtree counts and costs, bottom-up ---------------------------------------------------

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

// ---- 6: the layout ----------------------------------------------------------------------------

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
    sah_atomic_max_u(&p.counters[kSahDepth], depth);
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
    p.out_triangles[3 * at + 0] = make_float4(a.x, a.y, a.z, 0.0f);
    p.out_triangles[3 * at + 1] = make_float4(b.x, b.y, b.z, 0.0f);
    p.out_triangles[3 * at + 2] = make_float4(c.x, c.y, c.z, 0.0f);
    p.out_triangle_ids[at] = t;
}

#if !LUCENT_GPU_CODE
/// The kernels in launch order, for the GPU launcher and the CPU emulation alike.
enum class GpuSahPass { kReset, kInit, kBin, kSplit, kPartition, kCount, kEmit, kTriangles };

/// Runs the passes of a build over n >= 1 triangles: run(pass, threads, level) launches one,
/// tasks_of(parity) reads how many tasks the level about to run has (checked every 4 levels:
/// empty levels do nothing, and each read waits for the GPU).
template <class Run, class TasksOf>
void gpu_sah_build_passes(unsigned n, Run&& run, TasksOf&& tasks_of) {
    run(GpuSahPass::kReset, 1u, 0u);
    run(GpuSahPass::kInit, n, 0u);
    for (unsigned level = 0; level < kSahLevels; ++level) {
        if (level > 0 && level % 4 == 0 && tasks_of(level & 1u) == 0) break;
        run(GpuSahPass::kBin, n, level);
        run(GpuSahPass::kSplit, n / 2 + 1, level);  // a level has at most n / 2 tasks
        run(GpuSahPass::kPartition, n, level);
    }
    run(GpuSahPass::kCount, 2 * n - 1, 0u);
    run(GpuSahPass::kEmit, 2 * n - 1, 0u);
    run(GpuSahPass::kTriangles, n, 0u);
}

/// Bin words a level may need for n triangles: every task of c >= 2 triangles takes
/// 3 * min(32, c + 4) * kSahBinWords <= 3 * 3c * kSahBinWords (c + 4 <= 3c).
inline size_t gpu_sah_pool_words(unsigned n) {
    return size_t(9) * kSahBinWords * n + 3 * kSahBins * kSahBinWords;
}

/// One pass on the CPU, a thread at a time (the tests' emulation of the GPU build).
inline void gpu_sah_run_on_cpu(GpuSahBuildParams& p, GpuSahPass pass, unsigned threads,
                               unsigned level) {
    p.level = level;
    for (unsigned i = 0; i < threads; ++i) switch (pass) {
            case GpuSahPass::kReset: sah_reset(p, i); break;
            case GpuSahPass::kInit: sah_init(p, i); break;
            case GpuSahPass::kBin: sah_bin(p, i); break;
            case GpuSahPass::kSplit: sah_split(p, i); break;
            case GpuSahPass::kPartition: sah_partition(p, i); break;
            case GpuSahPass::kCount: sah_count(p, i); break;
            case GpuSahPass::kEmit: sah_emit(p, i); break;
            case GpuSahPass::kTriangles: sah_triangles(p, i); break;
        }
}
#endif

}  // namespace lucent::gpu

#if LUCENT_GPU_CODE
// The entry points the host launches (extern "C": unmangled names for cuModuleGetFunction).
#define LUCENT_SAH_KERNEL(name, body)                                              \
    extern "C" __global__ void name(lucent::gpu::GpuSahBuildParams p) {           \
        lucent::gpu::body(p, blockIdx.x * blockDim.x + threadIdx.x);              \
    }
LUCENT_SAH_KERNEL(lucent_sah_reset, sah_reset)
LUCENT_SAH_KERNEL(lucent_sah_init, sah_init)
LUCENT_SAH_KERNEL(lucent_sah_bin, sah_bin)
LUCENT_SAH_KERNEL(lucent_sah_split, sah_split)
LUCENT_SAH_KERNEL(lucent_sah_partition, sah_partition)
LUCENT_SAH_KERNEL(lucent_sah_count, sah_count)
LUCENT_SAH_KERNEL(lucent_sah_emit, sah_emit)
LUCENT_SAH_KERNEL(lucent_sah_triangles, sah_triangles)
#undef LUCENT_SAH_KERNEL
#endif  // LUCENT_GPU_CODE

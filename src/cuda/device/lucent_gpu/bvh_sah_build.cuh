// The GPU binned-SAH triangle BVH builder: the host builder's algorithm (src/accel/bvh.cpp,
// Wald 2007, "On fast construction of SAH-based bounding volume hierarchies": 32 bins per
// axis on the centroids, fewer for small nodes, the SAH leaf test, the median split near the
// depth limit) run on the GPU as in Garanzha, Pantaleoni and McAllister 2011 ("Simpler and
// faster HLBVH with work queues"): the big nodes breadth-first, one level of the tree at a
// time over all the GPU, the small ones (up to GpuSahBuildParams::small_limit triangles)
// each by one warp, depth-first in shared memory. It makes the host's tree (the same splits,
// up to the order of triangles inside a leaf), so it traces as fast, and writes the layout of
// triangle_bvh.cuh directly. H-PLOC (bvh_build.cuh) builds faster trees that trace at
// 0.85-0.99x of this one (docs/performance.md).
//
// Every node owns a range [begin, begin + count) of the leaf order; a split gives child 0
// the front of it. The passes, one kernel each (gpu_bvh_builder.cpp launches them):
//  1. lucent_sah_init:      each triangle's box; the root's box and centroid box.
//  2. lucent_sah_bin:       per level: each place of the leaf order still in a big task adds
//     its triangle's box to its task's bins; a block stages the bins of the task it mostly
//     holds in shared memory (one global atomic per bin and block, not per triangle).
//  3. lucent_sah_split:     per level, a warp per big task: sweeps its bins, and makes two
//     children: big ones are tasks of the next level, small ones go to the small-task list,
//     one triangle is a leaf at once.
//  4. lucent_sah_partition: per level: each triangle moves to its child's part of the range
//     (places handed out per block, again staged in shared memory).
//  5. lucent_sah_small:     a warp per small task: loads its triangles into shared memory
//     and builds its whole subtree, node after node (bin, sweep, partition among its lanes).
//  6. lucent_sah_count:     bottom-up, the inner nodes and the SAH cost of every subtree.
//  7. lucent_sah_emit:      each inner node finds its depth-first place (child 0 right after
//     its parent, as the host's layout) and writes its 64-byte node; lucent_sah_triangles
//     copies the triangles into leaf order.
//
// Every kernel body is a plain function built for the host too: a per-thread pass is a
// function of (params, thread); a per-block pass a function of (params, block, shared
// memory) written as steps (sah_step) with a barrier after each. Tests run the whole build on
// the CPU, a thread at a time (gpu_sah_run_on_cpu).
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
constexpr int kSahTaskBinWords = 3 * kSahBins * kSahBinWords;  // the bins of one big task
constexpr unsigned kSahLevels = 64;     // kSahMaxDepth + the leaves, with room
constexpr float kSahEmpty = 3.0e38f;    // the lo of an empty box (its hi is -kSahEmpty)
constexpr unsigned kSahBlock = 256;     // threads of the per-place passes (init, bin, partition)
constexpr unsigned kSahWarp = 32;       // threads of the per-task passes (split, small)
/// Small tasks hold at most this many triangles (the shared memory of lucent_sah_small);
/// GpuSahBuildParams::small_limit picks the limit at run time, from 28 (a big task has 32
/// bins) to this.
constexpr unsigned kSahSmallMax = 256;
constexpr unsigned kSahSmallMin = kSahBins - 4;
constexpr unsigned kSahSmallDefault = 64;
/// Pending nodes of a small task: the smaller child is built first, so at most
/// log2(kSahSmallMax) + 1 wait.
constexpr unsigned kSahSmallStack = 16;
constexpr unsigned kSahSmallBit = 0x80000000u;  // a child task that is a small one
constexpr unsigned kSahSmallBlocks = 4096;      // blocks of lucent_sah_small, at most

/// Words of GpuSahBuildParams::counters.
enum GpuSahCounter : int {
    kSahNextNode = 0,    // nodes are handed out in pairs from 1 (0 is the root)
    kSahTaskCount = 1,   // 2 words: big tasks of the even and the odd levels
    kSahSmallCount = 3,  // small tasks made
    kSahSmallNext = 4,   // small tasks taken by lucent_sah_small's blocks
    kSahBadIndex = 5,    // the first triangle with a vertex out of range, or kSahInvalid
    kSahDepth = 6,       // inner levels of the emitted tree
    kSahCost = 7,        // SAH cost of the tree (as the host's Bvh::sah_cost), float bits
    kSahInner = 8,       // inner nodes emitted
    kSahFault = 9,       // 0, or the first GpuSahFault
    kSahCounterCount = 10
};

enum GpuSahFault : unsigned {
    kSahFaultNone = 0,
    kSahFaultTasks = 1,      // more tasks than their lists hold
    kSahFaultNodes = 2,      // more than 2N - 1 nodes
    kSahFaultDeepTree = 3,   // a walk to the root longer than the traversal stack
    kSahFaultSmallStack = 4  // a small task's pending nodes outgrew kSahSmallStack
};

/// A big node of the level being built (more than small_limit triangles): its range of the
/// leaf order, its boxes (grown by the level above) and its decision.
struct GpuSahTask {
    unsigned node, begin, count, depth;
    int box[6];   // lo xyz, hi xyz as ordered integers
    int cbox[6];  // the box of the doubled centroids (lo + hi), likewise
    unsigned bin_count;   // bins per axis (min(32, count + 4), as the host); 0: the median
    unsigned decision;    // kSahDecideLeaf, kSahDecideMedian, or axis << 8 | bin
    unsigned left_count;  // triangles of child 0
    unsigned child[2];    // kSahInvalid (a one-triangle leaf), kSahSmallBit | small task,
                          // or the task of the next level
    unsigned child_node;  // node of child 0 (child 1 is the next one)
    unsigned sent[2];     // triangles given a place in each child so far
};

/// A node whose subtree one warp builds (lucent_sah_small).
struct GpuSahSmallTask {
    unsigned node, begin, count, depth;
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
    unsigned small_limit;  // tasks of up to this many triangles are small
    unsigned task_capacity, small_capacity;  // of tasks[k] and small
    // scratch, N = triangle_count
    float4* prim_lo;  // N triangle boxes
    float4* prim_hi;
    unsigned* work[2];        // N: the triangle at each place of the leaf order, by level parity
    unsigned* place_task[2];  // N: the big task of each place, kSahInvalid when it has none
    unsigned* order;          // N: triangles in leaf order
    GpuSahTask* tasks[2];     // big tasks of even and odd levels
    unsigned* bins[2];        // kSahTaskBinWords per big task, by level parity
    GpuSahSmallTask* small;
    float4* node_lo;    // 2N - 1 nodes: xyz, w = SAH cost of the subtree
    float4* node_hi;    // xyz, w unused
    uint2* node_range;  // inner: (child 0, 0); leaf: (first, count)
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

/// Big tasks of one level: they are disjoint and hold more than `small_limit` triangles.
LUCENT_HD inline unsigned gpu_sah_task_capacity(unsigned n, unsigned small_limit) {
    return n / (small_limit + 1) + 1;
}
/// Small tasks: disjoint, of 2 triangles or more (1 for a root of one triangle).
LUCENT_HD inline unsigned gpu_sah_small_capacity(unsigned n) {
    return n / 2 + 1;
}

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

/// The lo and hi of a triangle's box, and its doubled centroid.
LUCENT_HD inline void sah_prim_box(const GpuSahBuildParams& p, unsigned prim, float3& lo,
                                   float3& hi) {
    lo = sah_xyz(p.prim_lo[prim]);
    hi = sah_xyz(p.prim_hi[prim]);
}

/// Grows `into` by the box `from` (both ordered integers), one thread.
LUCENT_HD inline void sah_accumulate(int* into, const int* from) {
    for (int c = 0; c < 3; ++c) {
        into[c] = from[c] < into[c] ? from[c] : into[c];
        into[3 + c] = from[3 + c] > into[3 + c] ? from[3 + c] : into[3 + c];
    }
}

/// Grows the box `into` (shared by threads) by `from`, unless `from` is empty.
LUCENT_HD inline void sah_merge_box(int* into, const int* from) {
    if (from[0] > from[3]) return;  // empty: lo above hi
    for (int c = 0; c < 3; ++c) {
        sah_atomic_min(into + c, from[c]);
        sah_atomic_max(into + 3 + c, from[3 + c]);
    }
}

/// Grows a thread's own box (ordered integers) by a triangle's box, no atomics.
LUCENT_HD inline void sah_include(int* box, float3 lo, float3 hi) {
    const int b[6] = {sah_ordered(lo.x), sah_ordered(lo.y), sah_ordered(lo.z),
                      sah_ordered(hi.x), sah_ordered(hi.y), sah_ordered(hi.z)};
    sah_accumulate(box, b);
}

/// Where a task's triangles fall in its bins: the doubled centroids' lo and the host's scale
/// (bins * 0.99999 / extent; 0 for a flat axis, which is not split).
struct SahFrame {
    float3 clo, scale;
    unsigned bins;
};

LUCENT_HD inline SahFrame sah_frame(const int* cbox, unsigned bins) {
    float3 lo, hi;
    sah_box_of(cbox, lo, hi);
    const float b = (float)bins;
    auto scale = [&](float extent) { return extent > 0.0f ? b * 0.99999f / extent : 0.0f; };
    SahFrame f;
    f.clo = lo;
    f.scale = make_float3(scale(hi.x - lo.x), scale(hi.y - lo.y), scale(hi.z - lo.z));
    f.bins = bins;
    return f;
}

/// The host's bin_of: the bin of a triangle (box lo, hi) along axis k.
LUCENT_HD inline int sah_bin_of(const SahFrame& f, float3 lo, float3 hi, int k) {
    const int b =
        (int)((sah_axis(lo, k) + sah_axis(hi, k) - sah_axis(f.clo, k)) * sah_axis(f.scale, k));
    return b < 0 ? 0 : b > (int)f.bins - 1 ? (int)f.bins - 1 : b;
}

/// Adds a triangle to its bin along each axis (`bins`: 3 axes of f.bins bins, global or
/// shared memory).
LUCENT_HD inline void sah_add_to_bins(unsigned* bins, const SahFrame& f, float3 lo, float3 hi) {
    for (int k = 0; k < 3; ++k) {
        unsigned* bin = bins + (k * f.bins + (unsigned)sah_bin_of(f, lo, hi, k)) * kSahBinWords;
        sah_atomic_add(bin, 1u);
        sah_grow_box(reinterpret_cast<int*>(bin + 1), lo, hi);
    }
}

/// Sets `words` bin words to empty bins; thread t of `threads` does its share.
LUCENT_HD inline void sah_clear_bins(unsigned* bins, unsigned words, unsigned t, unsigned threads) {
    for (unsigned w = t; w < words; w += threads) {
        const unsigned word = w % kSahBinWords;
        bins[w] = word == 0   ? 0u
                  : word <= 3 ? (unsigned)sah_ordered(kSahEmpty)
                              : (unsigned)sah_ordered(-kSahEmpty);
    }
}

/// The best plane along one axis.
struct SahBest {
    float cost;
    int bin;  // planes are 1 .. bins - 1; 0: none
    unsigned left_count;
};

/// The host's sweep along one axis (bvh.cpp, Builder::build): right-to-left areas and counts,
/// then each plane's cost, the first strictly cheapest kept.
LUCENT_HD inline SahBest sah_sweep_axis(const unsigned* axis, unsigned nb) {
    SahBest best{3.402823e38f, 0, 0};
    float right_area[kSahBins];
    unsigned right_count[kSahBins];
    int acc[6];
    sah_clear_box(acc);
    unsigned count = 0;
    for (int b = (int)nb - 1; b > 0; --b) {
        const unsigned* bin = axis + b * kSahBinWords;
        sah_accumulate(acc, reinterpret_cast<const int*>(bin + 1));
        count += bin[0];
        float3 lo, hi;
        sah_box_of(acc, lo, hi);
        right_area[b] = sah_half_area(lo, hi);
        right_count[b] = count;
    }
    sah_clear_box(acc);
    count = 0;
    for (int b = 1; b < (int)nb; ++b) {
        const unsigned* bin = axis + (b - 1) * kSahBinWords;
        sah_accumulate(acc, reinterpret_cast<const int*>(bin + 1));
        count += bin[0];
        if (count == 0 || right_count[b] == 0) continue;
        float3 lo, hi;
        sah_box_of(acc, lo, hi);
        const float cost = sah_add(sah_mul(sah_half_area(lo, hi), (float)count),
                                   sah_mul(right_area[b], (float)right_count[b]));
        if (cost < best.cost) best = SahBest{cost, b, count};
    }
    return best;
}

/// The bins per axis of a node of `count` triangles at `depth` (the host's): none when the
/// depth guard forces the median split.
LUCENT_HD inline unsigned sah_bins_for(const GpuSahBuildParams& p, unsigned count, unsigned depth) {
    const unsigned leaves = (count + p.max_leaf_size - 1) / p.max_leaf_size;
    unsigned levels_needed = 0;  // std::bit_width
    for (unsigned v = leaves; v; v >>= 1) ++levels_needed;
    if (depth + levels_needed + 1 >= kSahMaxDepth) return 0;
    return count + 4 < (unsigned)kSahBins ? count + 4 : (unsigned)kSahBins;
}

/// A node's decision from its axes' best planes (one thread; `best` has 3 entries, skipped
/// for flat axes): the host's order, the first strictly cheapest axis.
struct SahDecision {
    unsigned decision;  // kSahDecideLeaf, kSahDecideMedian, or axis << 8 | bin
    unsigned left_count;
};

LUCENT_HD inline SahDecision sah_decide(const GpuSahBuildParams& p, unsigned n, float3 lo,
                                        float3 hi, const SahFrame& f, const SahBest* best) {
    int axis = -1;
    float best_cost = 3.402823e38f;
    for (int k = 0; k < 3; ++k)
        if (f.bins > 0 && sah_axis(f.scale, k) != 0.0f && best[k].bin > 0 &&
            best[k].cost < best_cost)
            axis = k, best_cost = best[k].cost;
    const float area = sah_half_area(lo, hi);
    bool leaf = n <= 1;
    if (!leaf && axis >= 0 && n <= p.max_leaf_size) {
        // SAH termination: a leaf when testing its triangles is no dearer than a split.
        const float split =
            sah_add(p.traversal_cost, sah_mul(p.intersection_cost, best_cost) / area);
        leaf = !(area > 0.0f) || sah_mul(p.intersection_cost, (float)n) <= split;
    }
    if (!leaf && axis < 0 && n <= p.max_leaf_size) leaf = true;
    if (leaf) return SahDecision{kSahDecideLeaf, n};
    // All centroids coincide, or near the depth limit: half and half (the host's median).
    if (axis < 0) return SahDecision{kSahDecideMedian, n / 2};
    return SahDecision{(unsigned)axis << 8 | (unsigned)best[axis].bin, best[axis].left_count};
}

/// The side of a triangle in a binned split (decision axis << 8 | bin).
LUCENT_HD inline unsigned sah_side(const SahFrame& f, unsigned decision, float3 lo, float3 hi) {
    const int k = (int)(decision >> 8), split_bin = (int)(decision & 0xffu);
    return sah_bin_of(f, lo, hi, k) < split_bin ? 0u : 1u;
}

LUCENT_HD inline void sah_write_node_box(const GpuSahBuildParams& p, unsigned node, float3 lo,
                                         float3 hi) {
    p.node_lo[node] = make_float4(lo.x, lo.y, lo.z, 0.0f);
    p.node_hi[node] = make_float4(hi.x, hi.y, hi.z, 0.0f);
}

/// One step of a block's work: f(thread) on every thread of the block, then a barrier. On
/// the CPU the threads run one after another: what a thread keeps from one step to the next
/// lives in the block's shared struct, indexed by thread, and a block's control flow reads
/// only shared values (the same for every thread).
template <class F>
LUCENT_HD inline void sah_step(unsigned threads, F&& f) {
#if LUCENT_GPU_CODE
    (void)threads;
    f(threadIdx.x);
    __syncthreads();
#else
    for (unsigned t = 0; t < threads; ++t) f(t);
#endif
}

// ---- 0, 1: the counters, the root, triangle boxes ----------------------------------------

/// One thread: the counters, and the root as the one big task of level 0 or a small task.
LUCENT_HD inline void sah_reset(const GpuSahBuildParams& p, unsigned i) {
    if (i != 0) return;
    for (int c = 0; c < kSahCounterCount; ++c) p.counters[c] = 0;
    const unsigned n = p.triangle_count;
    p.counters[kSahNextNode] = 1;
    p.counters[kSahBadIndex] = kSahInvalid;
    p.node_parent[0] = kSahInvalid;
    p.node_range[0] = make_uint2(0u, n);
    if (n <= p.small_limit) {
        p.small[0] = GpuSahSmallTask{0u, 0u, n, 0u};
        p.counters[kSahSmallCount] = 1;
        return;
    }
    GpuSahTask& root = p.tasks[0][0];
    root.node = 0, root.begin = 0, root.count = n, root.depth = 0;
    sah_clear_box(root.box);
    sah_clear_box(root.cbox);
    root.bin_count = sah_bins_for(p, n, 0u);
    root.sent[0] = root.sent[1] = 0;
    sah_clear_bins(p.bins[0], kSahTaskBinWords, 0u, 1u);
    p.counters[kSahTaskCount] = 1;
}

struct SahInitShared {
    int box[6], cbox[6];  // the root's, staged
};

/// Per block of kSahBlock places: each triangle's box; the block's share of the root's
/// boxes, merged into the root once.
LUCENT_HD inline void sah_init(const GpuSahBuildParams& p, unsigned block, unsigned threads,
                               SahInitShared& s) {
    const unsigned n = p.triangle_count;
    sah_step(threads, [&](unsigned t) {
        if (t == 0) sah_clear_box(s.box), sah_clear_box(s.cbox);
    });
    sah_step(threads, [&](unsigned t) {
        const unsigned i = block * threads + t;
        if (i >= n) return;
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
        const bool big_root = n > p.small_limit;
        p.work[0][i] = i;
        p.place_task[0][i] = big_root ? 0u : kSahInvalid;
        p.order[i] = i;          // a small root reads its triangles from here
        p.node_arrivals[i] = 0;  // 2N - 1 nodes: two each (the bottom-up pass counts on them)
        if (n + i < 2 * n - 1) p.node_arrivals[n + i] = 0;
        if (!big_root) return;
        sah_grow_box(s.box, lo, hi);
        const float3 c = lo + hi;  // doubled centroid, as the host keeps them
        sah_grow_box(s.cbox, c, c);
    });
    sah_step(threads, [&](unsigned t) {
        if (t != 0 || n <= p.small_limit) return;
        sah_merge_box(p.tasks[0][0].box, s.box);
        sah_merge_box(p.tasks[0][0].cbox, s.cbox);
    });
}

// ---- 2: bins of the big tasks ---------------------------------------------------------------

struct SahBinShared {
    unsigned tasks;  // big tasks of this level
    unsigned main;   // the task whose bins the block stages, or kSahInvalid
    SahFrame frame;
    unsigned bins[kSahTaskBinWords];
};

/// The task the block holds most of, about: the one of its middle place, if it bins.
LUCENT_HD inline unsigned sah_main_task(const GpuSahBuildParams& p, unsigned parity, unsigned block,
                                        unsigned threads) {
    unsigned middle = block * threads + threads / 2;
    if (middle >= p.triangle_count) middle = p.triangle_count - 1;
    return p.place_task[parity][middle];
}

LUCENT_HD inline void sah_bin(const GpuSahBuildParams& p, unsigned block, unsigned threads,
                              SahBinShared& s) {
    const unsigned parity = p.level & 1u;
    sah_step(threads, [&](unsigned t) {
        const unsigned i = block * threads + t;
        if (i < p.triangle_count) p.place_task[parity ^ 1u][i] = kSahInvalid;  // the next level's
        if (t != 0) return;
        // The next level's tasks are made by this level's split.
        if (block == 0) p.counters[kSahTaskCount + (parity ^ 1u)] = 0;
        s.tasks = p.counters[kSahTaskCount + parity];
        s.main = kSahInvalid;
        if (s.tasks == 0) return;
        const unsigned main = sah_main_task(p, parity, block, threads);
        if (main == kSahInvalid || p.tasks[parity][main].bin_count == 0) return;
        s.main = main;
        s.frame = sah_frame(p.tasks[parity][main].cbox, p.tasks[parity][main].bin_count);
    });
    if (s.tasks == 0) return;  // an empty level: the build has no more big tasks
    const unsigned main = s.main;
    const unsigned words = main == kSahInvalid ? 0u : 3 * s.frame.bins * kSahBinWords;
    if (words > 0)
        sah_step(threads, [&](unsigned t) { sah_clear_bins(s.bins, words, t, threads); });
    sah_step(threads, [&](unsigned t) {
        const unsigned i = block * threads + t;
        if (i >= p.triangle_count) return;
        const unsigned ti = p.place_task[parity][i];
        if (ti == kSahInvalid) return;
        const GpuSahTask& task = p.tasks[parity][ti];
        if (task.bin_count == 0) return;  // a median split: no bins
        float3 lo, hi;
        sah_prim_box(p, p.work[parity][i], lo, hi);
        if (ti == main) {
            sah_add_to_bins(s.bins, s.frame, lo, hi);
        } else {
            sah_add_to_bins(p.bins[parity] + ti * kSahTaskBinWords,
                            sah_frame(task.cbox, task.bin_count), lo, hi);
        }
    });
    if (words == 0) return;
    sah_step(threads, [&](unsigned t) {  // one atomic per word of each bin that holds any
        unsigned* global = p.bins[parity] + main * kSahTaskBinWords;
        for (unsigned b = t; b < 3 * s.frame.bins; b += threads) {
            const unsigned* bin = s.bins + b * kSahBinWords;
            if (bin[0] == 0) continue;
            sah_atomic_add(global + b * kSahBinWords, bin[0]);
            sah_merge_box(reinterpret_cast<int*>(global + b * kSahBinWords + 1),
                          reinterpret_cast<const int*>(bin + 1));
        }
    });
}

// ---- 3: split, a warp per big task ----------------------------------------------------------

struct SahSplitShared {
    unsigned tasks;
    SahFrame frame;
    SahBest best[3];
    unsigned new_tasks[2];  // big children made, whose bins the warp clears
    unsigned bins[kSahTaskBinWords];
};

/// Makes a child of `count` triangles over [begin, ...): kSahInvalid for one triangle (a
/// leaf at once), a small task, or a big task of the next level (its bins cleared by the
/// caller).
LUCENT_HD inline unsigned sah_make_child(const GpuSahBuildParams& p, unsigned node, unsigned begin,
                                         unsigned count, unsigned depth) {
    p.node_range[node] = make_uint2(begin, count);  // a leaf unless it is split
    if (count <= 1) return kSahInvalid;
    if (count <= p.small_limit) {
        const unsigned si = sah_atomic_add(&p.counters[kSahSmallCount], 1u);
        if (si >= p.small_capacity) {
            sah_atomic_first(&p.counters[kSahFault], kSahFaultTasks);
            return kSahInvalid;
        }
        p.small[si] = GpuSahSmallTask{node, begin, count, depth};
        return kSahSmallBit | si;
    }
    const unsigned parity = (p.level + 1) & 1u;
    const unsigned ti = sah_atomic_add(&p.counters[kSahTaskCount + parity], 1u);
    if (ti >= p.task_capacity) {
        sah_atomic_first(&p.counters[kSahFault], kSahFaultTasks);
        return kSahInvalid;
    }
    GpuSahTask& t = p.tasks[parity][ti];
    t.node = node, t.begin = begin, t.count = count, t.depth = depth;
    sah_clear_box(t.box);
    sah_clear_box(t.cbox);
    t.bin_count = sah_bins_for(p, count, depth);
    t.sent[0] = t.sent[1] = 0;
    return ti;
}

LUCENT_HD inline void sah_split(const GpuSahBuildParams& p, unsigned block, unsigned threads,
                                SahSplitShared& s) {
    const unsigned parity = p.level & 1u;
    sah_step(threads, [&](unsigned t) {
        if (t != 0) return;
        s.tasks = p.counters[kSahTaskCount + parity];
        if (block < s.tasks) {
            const GpuSahTask& task = p.tasks[parity][block];
            s.frame = sah_frame(task.cbox, task.bin_count);
        }
    });
    if (block >= s.tasks) return;
    GpuSahTask& task = p.tasks[parity][block];
    const unsigned nb = s.frame.bins;
    if (nb > 0) {
        sah_step(threads, [&](unsigned t) {  // the bins into shared memory, for the sweeps
            const unsigned* global = p.bins[parity] + block * kSahTaskBinWords;
            for (unsigned w = t; w < 3 * nb * kSahBinWords; w += threads) s.bins[w] = global[w];
        });
        sah_step(threads, [&](unsigned t) {
            if (t < 3) s.best[t] = sah_sweep_axis(s.bins + t * nb * kSahBinWords, nb);
        });
    }
    sah_step(threads, [&](unsigned t) {
        if (t != 0) return;
        s.new_tasks[0] = s.new_tasks[1] = kSahInvalid;
        float3 lo, hi;
        sah_box_of(task.box, lo, hi);
        sah_write_node_box(p, task.node, lo, hi);
        const unsigned n = task.count;
        const SahDecision d = sah_decide(p, n, lo, hi, s.frame, s.best);
        task.decision = d.decision;
        task.left_count = d.left_count;
        if (d.decision == kSahDecideLeaf) {
            p.node_range[task.node] = make_uint2(task.begin, n);
            return;
        }
        const unsigned c0 = sah_atomic_add(&p.counters[kSahNextNode], 2u);
        if (c0 + 2 > 2 * p.triangle_count - 1) {
            sah_atomic_first(&p.counters[kSahFault], kSahFaultNodes);
            task.decision = kSahDecideLeaf;  // keeps the partition in bounds; the build fails
            return;
        }
        task.child_node = c0;
        p.node_range[task.node] = make_uint2(c0, 0u);
        p.node_parent[c0] = task.node;
        p.node_parent[c0 + 1] = task.node;
        const unsigned counts[2] = {d.left_count, n - d.left_count};
        for (unsigned side = 0; side < 2; ++side) {
            const unsigned child = sah_make_child(p, c0 + side, task.begin + side * d.left_count,
                                                  counts[side], task.depth + 1);
            task.child[side] = child;
            if (child != kSahInvalid && !(child & kSahSmallBit)) s.new_tasks[side] = child;
        }
    });
    sah_step(threads, [&](unsigned t) {
        for (unsigned side = 0; side < 2; ++side)
            if (s.new_tasks[side] != kSahInvalid)
                sah_clear_bins(p.bins[parity ^ 1u] + s.new_tasks[side] * kSahTaskBinWords,
                               kSahTaskBinWords, t, threads);
    });
}

// ---- 4: partition ---------------------------------------------------------------------------

struct SahPartitionShared {
    unsigned tasks;
    unsigned main;  // the task whose places the block hands out
    SahFrame frame;
    unsigned count[2], base[2];  // its triangles of this block going to each side
    int box[2][6], cbox[2][6];   // and their boxes, for big children
    unsigned slot[kSahBlock];    // each thread's place among its side's, or kSahInvalid
    unsigned char side[kSahBlock];
};

/// Puts triangle `prim` at place `at` of child `side` of task `t`: a leaf's triangle, a small
/// task's, or a big task's of the next level, whose boxes it grows unless `staged`.
LUCENT_HD inline void sah_place(const GpuSahBuildParams& p, const GpuSahTask& t, unsigned side,
                                unsigned at, unsigned prim, float3 lo, float3 hi, bool staged) {
    const unsigned child = t.child[side];
    if (child == kSahInvalid) {  // a one-triangle leaf
        sah_write_node_box(p, t.child_node + side, lo, hi);
        p.order[at] = prim;
        return;
    }
    if (child & kSahSmallBit) {
        p.order[at] = prim;
        return;
    }
    const unsigned parity = (p.level + 1) & 1u;
    p.work[parity][at] = prim;
    p.place_task[parity][at] = child;
    if (staged) return;
    GpuSahTask& c = p.tasks[parity][child];
    sah_grow_box(c.box, lo, hi);
    const float3 centroid = lo + hi;
    sah_grow_box(c.cbox, centroid, centroid);
}

LUCENT_HD inline bool sah_child_is_big(const GpuSahTask& t, unsigned side) {
    return t.child[side] != kSahInvalid && !(t.child[side] & kSahSmallBit);
}

LUCENT_HD inline void sah_partition(const GpuSahBuildParams& p, unsigned block, unsigned threads,
                                    SahPartitionShared& s) {
    const unsigned parity = p.level & 1u;
    sah_step(threads, [&](unsigned t) {
        if (t != 0) return;
        s.tasks = p.counters[kSahTaskCount + parity];
        s.main = kSahInvalid;
        if (s.tasks == 0) return;
        const unsigned main = sah_main_task(p, parity, block, threads);
        if (main == kSahInvalid) return;
        const GpuSahTask& task = p.tasks[parity][main];
        if (task.decision == kSahDecideLeaf || task.decision == kSahDecideMedian) return;
        s.main = main;
        s.frame = sah_frame(task.cbox, task.bin_count);
        for (int side = 0; side < 2; ++side) {
            s.count[side] = 0;
            sah_clear_box(s.box[side]);
            sah_clear_box(s.cbox[side]);
        }
    });
    if (s.tasks == 0) return;
    sah_step(threads, [&](unsigned t) {
        s.slot[t] = kSahInvalid;
        const unsigned i = block * threads + t;
        if (i >= p.triangle_count) return;
        const unsigned ti = p.place_task[parity][i];
        if (ti == kSahInvalid) return;
        GpuSahTask& task = p.tasks[parity][ti];
        const unsigned prim = p.work[parity][i];
        float3 lo, hi;
        sah_prim_box(p, prim, lo, hi);
        if (task.decision == kSahDecideLeaf) {  // only after a fault: keeps the places
            p.order[i] = prim;
            return;
        }
        if (task.decision == kSahDecideMedian) {  // the front half to child 0, in place
            sah_place(p, task, i - task.begin < task.left_count ? 0u : 1u, i, prim, lo, hi, false);
            return;
        }
        const unsigned side =
            ti == s.main ? sah_side(s.frame, task.decision, lo, hi)
                         : sah_side(sah_frame(task.cbox, task.bin_count), task.decision, lo, hi);
        if (ti != s.main) {
            const unsigned at =
                task.begin + side * task.left_count + sah_atomic_add(&task.sent[side], 1u);
            sah_place(p, task, side, at, prim, lo, hi, false);
            return;
        }
        s.side[t] = (unsigned char)side;
        s.slot[t] = sah_atomic_add(&s.count[side], 1u);
        if (sah_child_is_big(task, side)) {
            sah_grow_box(s.box[side], lo, hi);
            const float3 centroid = lo + hi;
            sah_grow_box(s.cbox[side], centroid, centroid);
        }
    });
    if (s.main == kSahInvalid) return;
    sah_step(threads, [&](unsigned t) {  // the block's places in each child, and its boxes
        if (t != 0) return;
        GpuSahTask& task = p.tasks[parity][s.main];
        for (unsigned side = 0; side < 2; ++side) {
            if (s.count[side] == 0) continue;
            s.base[side] = sah_atomic_add(&task.sent[side], s.count[side]);
            if (!sah_child_is_big(task, side)) continue;
            GpuSahTask& c = p.tasks[parity ^ 1u][task.child[side]];
            sah_merge_box(c.box, s.box[side]);
            sah_merge_box(c.cbox, s.cbox[side]);
        }
    });
    sah_step(threads, [&](unsigned t) {
        if (s.slot[t] == kSahInvalid) return;
        const unsigned i = block * threads + t;
        const GpuSahTask& task = p.tasks[parity][s.main];
        const unsigned side = s.side[t];
        const unsigned prim = p.work[parity][i];
        float3 lo, hi;
        sah_prim_box(p, prim, lo, hi);
        sah_place(p, task, side, task.begin + side * task.left_count + s.base[side] + s.slot[t],
                  prim, lo, hi, true);
    });
}

// ---- 5: small tasks, a warp each ------------------------------------------------------------

struct SahSmallShared {
    unsigned have;                          // a task was taken
    GpuSahSmallTask task;                   // the small task (its node is the subtree's root)
    GpuSahSmallTask stack[kSahSmallStack];  // pending nodes, begin relative to the task's
    unsigned stack_size;
    GpuSahSmallTask node;  // the node being built, begin relative
    unsigned active;
    int box[6], cbox[6];
    SahFrame frame;
    SahBest best[3];
    SahDecision decision;
    unsigned child_node, fill[2];
    unsigned prim[kSahSmallMax];  // the task's triangles, by local index
    float3 lo[kSahSmallMax], hi[kSahSmallMax];
    unsigned short ids[kSahSmallMax];  // local indices in leaf order
    unsigned short ids_next[kSahSmallMax];
    unsigned bins[kSahTaskBinWords];
};

/// Builds the node in s.node (the task's triangles in shared memory): its boxes, bins, sweep
/// and decision, then its children pushed and its triangles partitioned between them.
LUCENT_HD inline void sah_small_node(const GpuSahBuildParams& p, unsigned threads,
                                     SahSmallShared& s) {
    const unsigned begin = s.node.begin, n = s.node.count;
    sah_step(threads, [&](unsigned t) {
        int box[6], cbox[6];
        sah_clear_box(box);
        sah_clear_box(cbox);
        for (unsigned j = t; j < n; j += threads) {
            const unsigned k = s.ids[begin + j];
            sah_include(box, s.lo[k], s.hi[k]);
            const float3 c = s.lo[k] + s.hi[k];
            sah_include(cbox, c, c);
        }
        sah_merge_box(s.box, box);
        sah_merge_box(s.cbox, cbox);
    });
    sah_step(threads, [&](unsigned t) {
        if (t != 0) return;
        float3 lo, hi;
        sah_box_of(s.box, lo, hi);
        sah_write_node_box(p, s.node.node, lo, hi);
        s.frame = sah_frame(s.cbox, n >= 2 ? sah_bins_for(p, n, s.node.depth) : 0u);
    });
    const unsigned nb = s.frame.bins;
    if (nb > 0) {
        sah_step(threads,
                 [&](unsigned t) { sah_clear_bins(s.bins, 3 * nb * kSahBinWords, t, threads); });
        sah_step(threads, [&](unsigned t) {
            for (unsigned j = t; j < n; j += threads) {
                const unsigned k = s.ids[begin + j];
                sah_add_to_bins(s.bins, s.frame, s.lo[k], s.hi[k]);
            }
        });
        sah_step(threads, [&](unsigned t) {
            if (t < 3) s.best[t] = sah_sweep_axis(s.bins + t * nb * kSahBinWords, nb);
        });
    }
    sah_step(threads, [&](unsigned t) {
        if (t != 0) return;
        float3 lo, hi;
        sah_box_of(s.box, lo, hi);
        s.decision = sah_decide(p, n, lo, hi, s.frame, s.best);
        const unsigned at = s.task.begin + begin;
        if (s.decision.decision == kSahDecideLeaf) {
            p.node_range[s.node.node] = make_uint2(at, n);
            return;
        }
        const unsigned c0 = sah_atomic_add(&p.counters[kSahNextNode], 2u);
        if (c0 + 2 > 2 * p.triangle_count - 1) {
            sah_atomic_first(&p.counters[kSahFault], kSahFaultNodes);
            s.decision.decision = kSahDecideLeaf;
            p.node_range[s.node.node] = make_uint2(at, n);
            return;
        }
        s.child_node = c0;
        s.fill[0] = s.fill[1] = 0;
        p.node_range[s.node.node] = make_uint2(c0, 0u);
        p.node_parent[c0] = s.node.node;
        p.node_parent[c0 + 1] = s.node.node;
        const unsigned left = s.decision.left_count;
        const GpuSahSmallTask child[2] = {{c0, begin, left, s.node.depth + 1},
                                          {c0 + 1, begin + left, n - left, s.node.depth + 1}};
        for (int side = 0; side < 2; ++side)
            p.node_range[child[side].node] =
                make_uint2(s.task.begin + child[side].begin, child[side].count);
        // The larger child waits, the smaller is built next: the stack stays short.
        const int first = child[0].count >= child[1].count ? 0 : 1;
        for (int q = 0; q < 2; ++q) {
            const int side = q == 0 ? first : 1 - first;
            if (child[side].count <= 1) continue;  // a leaf; its box comes with its triangle
            if (s.stack_size >= kSahSmallStack) {
                sah_atomic_first(&p.counters[kSahFault], kSahFaultSmallStack);
                continue;
            }
            s.stack[s.stack_size++] = child[side];
        }
    });
    if (s.decision.decision == kSahDecideLeaf) return;
    const unsigned left = s.decision.left_count;
    if (s.decision.decision == kSahDecideMedian) {  // the front half to child 0, in place
        sah_step(threads, [&](unsigned t) {
            for (unsigned side = t; side < 2; side += threads) {
                if ((side == 0 ? left : n - left) != 1) continue;
                const unsigned k = s.ids[begin + side * left];
                sah_write_node_box(p, s.child_node + side, s.lo[k], s.hi[k]);
            }
        });
        return;
    }
    sah_step(threads, [&](unsigned t) {
        for (unsigned j = t; j < n; j += threads) {
            const unsigned k = s.ids[begin + j];
            const unsigned side = sah_side(s.frame, s.decision.decision, s.lo[k], s.hi[k]);
            const unsigned at = side * left + sah_atomic_add(&s.fill[side], 1u);
            s.ids_next[begin + at] = (unsigned short)k;
            if ((side == 0 ? left : n - left) == 1)
                sah_write_node_box(p, s.child_node + side, s.lo[k], s.hi[k]);
        }
    });
    sah_step(threads, [&](unsigned t) {
        for (unsigned j = t; j < n; j += threads) s.ids[begin + j] = s.ids_next[begin + j];
    });
}

/// Per block of kSahWarp threads: takes small tasks one after another and builds each one's
/// subtree.
LUCENT_HD inline void sah_small(const GpuSahBuildParams& p, unsigned threads, SahSmallShared& s) {
    for (;;) {
        sah_step(threads, [&](unsigned t) {
            if (t != 0) return;
            const unsigned ti = sah_atomic_add(&p.counters[kSahSmallNext], 1u);
            s.have = ti < p.counters[kSahSmallCount] && ti < p.small_capacity;
            if (s.have) s.task = p.small[ti];
        });
        if (!s.have) return;
        const unsigned n = s.task.count;
        sah_step(threads, [&](unsigned t) {
            for (unsigned j = t; j < n; j += threads) {
                const unsigned prim = p.order[s.task.begin + j];
                s.prim[j] = prim;
                sah_prim_box(p, prim, s.lo[j], s.hi[j]);
                s.ids[j] = (unsigned short)j;
            }
            if (t != 0) return;
            s.stack[0] = GpuSahSmallTask{s.task.node, 0u, n, s.task.depth};
            s.stack_size = 1;
        });
        for (;;) {
            sah_step(threads, [&](unsigned t) {
                if (t != 0) return;
                s.active = s.stack_size > 0;
                if (!s.active) return;
                s.node = s.stack[--s.stack_size];
                sah_clear_box(s.box);
                sah_clear_box(s.cbox);
            });
            if (!s.active) break;
            sah_small_node(p, threads, s);
        }
        sah_step(threads, [&](unsigned t) {
            for (unsigned j = t; j < n; j += threads) p.order[s.task.begin + j] = s.prim[s.ids[j]];
        });
    }
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
enum class GpuSahPass {
    kReset,
    kInit,
    kBin,
    kSplit,
    kPartition,
    kSmall,
    kCount,
    kEmit,
    kTriangles,
    kPassCount
};

/// Blocks and threads of each pass.
struct GpuSahShape {
    unsigned blocks, threads;
};

inline GpuSahShape gpu_sah_shape(GpuSahPass pass, unsigned n, unsigned small_limit) {
    auto over = [](size_t items, unsigned threads) {
        return GpuSahShape{unsigned((items + threads - 1) / threads), threads};
    };
    switch (pass) {
        case GpuSahPass::kReset:
            return GpuSahShape{1, kSahWarp};
        case GpuSahPass::kSplit:
            return GpuSahShape{gpu_sah_task_capacity(n, small_limit), kSahWarp};
        case GpuSahPass::kSmall: {
            const unsigned tasks = gpu_sah_small_capacity(n);
            return GpuSahShape{tasks < kSahSmallBlocks ? tasks : kSahSmallBlocks, kSahWarp};
        }
        case GpuSahPass::kCount:
        case GpuSahPass::kEmit:
            return over(2 * size_t(n) - 1, 128);
        case GpuSahPass::kTriangles:
            return over(n, 128);
        default:
            return over(n, kSahBlock);  // init, bin, partition: a thread per place
    }
}

/// Levels launched before the first read of a level's task count (each read waits for the
/// GPU; an empty level costs three launches that return at once): 1.5 times the levels of a
/// balanced tree down to the small tasks, and 2, as SAH trees are not balanced (Sponza,
/// Sibenik, the bunny and the dragon have 11-15 levels of big tasks for 15-17 launched).
inline unsigned gpu_sah_unread_levels(unsigned n, unsigned small_limit) {
    const unsigned balanced = unsigned(std::bit_width(n / small_limit));
    return balanced + balanced / 2 + 2;
}

/// Runs the passes of a build over n >= 1 triangles: run(pass, level) launches one,
/// tasks_of(parity) reads how many big tasks the level about to run has (after the first
/// gpu_sah_unread_levels levels, every 4 levels).
template <class Run, class TasksOf>
void gpu_sah_build_passes(unsigned n, unsigned small_limit, Run&& run, TasksOf&& tasks_of) {
    run(GpuSahPass::kReset, 0u);
    run(GpuSahPass::kInit, 0u);
    if (n > small_limit) {
        const unsigned unread = gpu_sah_unread_levels(n, small_limit);
        for (unsigned level = 0; level < kSahLevels; ++level) {
            if (level >= unread && (level - unread) % 4 == 0 && tasks_of(level & 1u) == 0) break;
            run(GpuSahPass::kBin, level);
            run(GpuSahPass::kSplit, level);
            run(GpuSahPass::kPartition, level);
        }
    }
    run(GpuSahPass::kSmall, 0u);
    run(GpuSahPass::kCount, 0u);
    run(GpuSahPass::kEmit, 0u);
    run(GpuSahPass::kTriangles, 0u);
}

/// Words of scratch a build of n triangles needs beyond its nodes (for the launcher and the
/// emulation alike).
struct GpuSahScratch {
    size_t task_capacity, small_capacity, bin_words;
};
inline GpuSahScratch gpu_sah_scratch(unsigned n, unsigned small_limit) {
    const size_t tasks = gpu_sah_task_capacity(n, small_limit);
    return GpuSahScratch{tasks, gpu_sah_small_capacity(n), tasks * kSahTaskBinWords};
}

/// One pass on the CPU, a thread at a time (the tests' emulation of the GPU build).
inline void gpu_sah_run_on_cpu(GpuSahBuildParams& p, GpuSahPass pass, unsigned level) {
    p.level = level;
    const GpuSahShape shape = gpu_sah_shape(pass, p.triangle_count, p.small_limit);
    for (unsigned b = 0; b < shape.blocks; ++b) {
        const unsigned first = b * shape.threads;
        switch (pass) {
            case GpuSahPass::kReset:
                for (unsigned t = 0; t < shape.threads; ++t) sah_reset(p, first + t);
                break;
            case GpuSahPass::kInit: {
                SahInitShared s;
                sah_init(p, b, shape.threads, s);
                break;
            }
            case GpuSahPass::kBin: {
                SahBinShared s;
                sah_bin(p, b, shape.threads, s);
                break;
            }
            case GpuSahPass::kSplit: {
                SahSplitShared s;
                sah_split(p, b, shape.threads, s);
                break;
            }
            case GpuSahPass::kPartition: {
                SahPartitionShared s;
                sah_partition(p, b, shape.threads, s);
                break;
            }
            case GpuSahPass::kSmall: {
                SahSmallShared s;
                sah_small(p, shape.threads, s);
                break;
            }
            case GpuSahPass::kCount:
                for (unsigned t = 0; t < shape.threads; ++t) sah_count(p, first + t);
                break;
            case GpuSahPass::kEmit:
                for (unsigned t = 0; t < shape.threads; ++t) sah_emit(p, first + t);
                break;
            case GpuSahPass::kTriangles:
                for (unsigned t = 0; t < shape.threads; ++t) sah_triangles(p, first + t);
                break;
            case GpuSahPass::kPassCount:
                break;
        }
    }
}
#endif

}  // namespace lucent::gpu

#if LUCENT_GPU_CODE
// The entry points the host launches (extern "C": unmangled names for cuModuleGetFunction).
#define LUCENT_SAH_THREAD_KERNEL(name, body, threads)                                              \
    extern "C" __global__ void __launch_bounds__(threads) name(lucent::gpu::GpuSahBuildParams p) { \
        lucent::gpu::body(p, blockIdx.x* blockDim.x + threadIdx.x);                                \
    }
#define LUCENT_SAH_BLOCK_KERNEL(name, body, shared, threads)                                       \
    extern "C" __global__ void __launch_bounds__(threads) name(lucent::gpu::GpuSahBuildParams p) { \
        __shared__ lucent::gpu::shared s;                                                          \
        lucent::gpu::body(p, blockIdx.x, blockDim.x, s);                                           \
    }
LUCENT_SAH_THREAD_KERNEL(lucent_sah_reset, sah_reset, 32)
LUCENT_SAH_BLOCK_KERNEL(lucent_sah_init, sah_init, SahInitShared, 256)
LUCENT_SAH_BLOCK_KERNEL(lucent_sah_bin, sah_bin, SahBinShared, 256)
LUCENT_SAH_BLOCK_KERNEL(lucent_sah_split, sah_split, SahSplitShared, 32)
LUCENT_SAH_BLOCK_KERNEL(lucent_sah_partition, sah_partition, SahPartitionShared, 256)
extern "C" __global__ void __launch_bounds__(32)
    lucent_sah_small(lucent::gpu::GpuSahBuildParams p) {
    __shared__ lucent::gpu::SahSmallShared s;
    lucent::gpu::sah_small(p, blockDim.x, s);
}
LUCENT_SAH_THREAD_KERNEL(lucent_sah_count, sah_count, 128)
LUCENT_SAH_THREAD_KERNEL(lucent_sah_emit, sah_emit, 128)
LUCENT_SAH_THREAD_KERNEL(lucent_sah_triangles, sah_triangles, 128)
#undef LUCENT_SAH_THREAD_KERNEL
#undef LUCENT_SAH_BLOCK_KERNEL
#endif  // LUCENT_GPU_CODE

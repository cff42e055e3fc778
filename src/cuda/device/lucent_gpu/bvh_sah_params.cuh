// The GPU binned-SAH builder's (bvh_sah_build.cuh) constants, counters, faults, tasks and the
// parameters every pass gets: what the host's launcher (gpu_bvh_builder.cpp) and the
// kernels share.
#pragma once

#include "lucent/device/platform.h"
#include "lucent/device/types.h"
#include "lucent_gpu/triangle_bvh.cuh"

namespace lucent::gpu {

constexpr unsigned kSahInvalid = 0xffffffffu;
constexpr int kSahBins = 32;           // the host's BuildOptions::bins
constexpr unsigned kSahMaxDepth = 60;  // the host's kMaxDepth: deeper gets median splits
constexpr int kSahBinWords = 7;        // count, lo xyz, hi xyz (ordered integers)
constexpr int kSahTaskBinWords = 3 * kSahBins * kSahBinWords;  // the bins of one big task
constexpr unsigned kSahLevels = 64;   // kSahMaxDepth + the leaves, with room
constexpr float kSahEmpty = 3.0e38f;  // the lo of an empty box (its hi is -kSahEmpty)
constexpr unsigned kSahBlock = 256;   // threads of the per-place passes (init, bin, partition)
constexpr unsigned kSahWarp = 32;     // threads of the per-task passes (split, small)
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
    int box[6];           // lo xyz, hi xyz as ordered integers
    int cbox[6];          // the box of the doubled centroids (lo + hi), likewise
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
    unsigned level;                          // the level the per-level kernels work on
    unsigned small_limit;                    // tasks of up to this many triangles are small
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

}  // namespace lucent::gpu

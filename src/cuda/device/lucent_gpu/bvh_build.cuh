// The GPU triangle BVH builder: H-PLOC (Benthin, Meister, Barczak, Mehalwal, Tsakok and
// Kensler 2024, "H-PLOC: Hierarchical Parallel Locally-Ordered Clustering for Bounding
// Volume Hierarchy Construction", HPG 2024), writing the layout of triangle_bvh.cuh
// directly. Compiled by NVRTC (src/cuda/accel/gpu_bvh_builder.cpp launches it).
//
// The passes, one kernel each (after lucent_build_reset, which clears the counters):
//  1. lucent_build_bounds:  the box of the triangle centroids (ordered-integer atomics).
//  2. lucent_build_morton:  a 30-bit Morton code per triangle (Karras 2012, Sec. 4).
//  3. lucent_radix_*:       a stable LSD radix sort of (code, triangle), 8 bits a pass.
//  4. lucent_build_leaves:  one leaf node per triangle, in code order.
//  5. lucent_build_hploc:   the hierarchy. Each thread climbs from its leaf as in Apetrei
//     2014 ("Fast and simply bottom-up BVH construction", the parent chosen by the smaller
//     of the code differences on either side; the second child to arrive goes on). Where a
//     subtree of the LBVH grows past kPlocClusters leaves, the warp runs PLOC (Meister and
//     Bittner 2018) on its clusters: every cluster finds its nearest neighbour by the
//     surface area of their union, mutual neighbours merge, until at most kPlocClusters
//     are left (one at the root). The tree is therefore built by SAH-like agglomeration,
//     not by the Morton splits, which is what keeps its quality near a sweep-SAH build.
//     Each new node also decides, by the SAH, whether its subtree becomes one leaf of up
//     to max_leaf_size triangles (leaf cost Ci * n * A against Ct * A + cost of children).
//  6. lucent_build_emit:    each inner node that remains finds its place in the depth-first
//     order (child 0 right after its parent) by walking up to the root, and writes its
//     64-byte node, the triangles of its leaf children and the parent links refit needs.
//
// Refit is bvh_refit.cuh.
#pragma once

#include "lucent/device/platform.h"
#include "lucent/device/types.h"
#include "lucent_gpu/radix_sort.cuh"
#include "lucent_gpu/triangle_bvh.cuh"

namespace lucent::gpu {

constexpr unsigned kBuildInvalid = 0xffffffffu;
constexpr int kPlocClusters = 16;  // clusters a subtree keeps: two halves fill a warp
#ifndef LUCENT_PLOC_RADIUS
#define LUCENT_PLOC_RADIUS 16
#endif
// Morton cells: cubes (one scale for the three axes, the largest extent), or 0 for boxes
// stretched to the scene's extent on each axis. Cubes keep the code order spatially even in
// long scenes (Sponza, Sibenik): on the H200, the worst of 18 trace ratios against the host
// SAH tree rose from 0.825x to 0.845x-0.852x (docs/performance.md).
#ifndef LUCENT_MORTON_CUBE
#define LUCENT_MORTON_CUBE 1
#endif
constexpr int kPlocRadius = LUCENT_PLOC_RADIUS;  // neighbours searched on each side

/// Words of GpuBuildParams::counters.
enum GpuBuildCounter : int {
    kCounterNextNode = 0,  // internal nodes are allocated from N upwards
    kCounterRoot = 1,      // the root node, once H-PLOC reaches it
    kCounterDepth = 2,     // inner levels of the emitted tree
    kCounterBadIndex = 3,  // the first triangle with a vertex out of range, or kBuildInvalid
    kCounterBounds = 4,    // 6 words: centroid lo.xyz, hi.xyz as ordered integers
    kCounterSah = 10,      // SAH cost of the emitted tree, as float bits
    kCounterInner = 11,    // inner nodes emitted
    kCounterFault = 12,    // 0, or the first GpuBuildFault a kernel met
    kCounterCount = 13
};

/// Internal checks that stop a kernel instead of letting it loop or write out of bounds.
enum GpuBuildFault : unsigned {
    kFaultNone = 0,
    kFaultNoMutualPair = 1,  // PLOC found no pair to merge
    kFaultNodeOverflow = 2,  // more than N - 1 inner nodes
    kFaultDeepTree = 3,      // a walk to the root longer than the traversal stack (input
                             // can do this: GpuBvhTooDeep, the host builds it instead)
    kFaultLeafTooBig = 4,    // a leaf subtree with more than kGpuMaxLeafSize triangles
};

/// Everything the build kernels read and write (device pointers).
struct GpuBuildParams {
    const float3* positions;
    const uint3* indices;  // null: triangle i is positions[3i .. 3i + 2]
    unsigned vertex_count;
    unsigned triangle_count;
    unsigned max_leaf_size;
    float traversal_cost, intersection_cost;
    // scratch, N = triangle_count
    unsigned* keys;         // N Morton codes, sorted in place by the radix passes
    unsigned* order;        // N triangles in code order
    unsigned* split_slots;  // N: Apetrei's exchange, one per split between two leaves
    unsigned* clusters;     // N: H-PLOC's cluster lists, at the start of each range
    float4* node_lo;        // 2N - 1 nodes: xyz, w = SAH cost of the subtree
    float4* node_hi;        // xyz, w = triangle count (bits)
    int2* node_children;    // leaves 0..N-1 have none
    unsigned* node_inner;   // inner nodes the subtree emits; 0 = it is emitted as one leaf
    unsigned* node_parent;
    unsigned* counters;  // GpuBuildCounter
    // the layout (triangle_bvh.cuh)
    float4* out_nodes;
    float4* out_triangles;
    unsigned* out_triangle_ids;
    unsigned* out_parents;  // per emitted node: parent << 1 | slot, kBuildInvalid at the root
};

#if LUCENT_GPU_CODE

constexpr unsigned kFullMask = 0xffffffffu;

// ---- small helpers --------------------------------------------------------------------

__device__ inline int ordered_int(float f) {  // monotonic float -> int, for atomicMin/Max
    const int i = __float_as_int(f);
    return i >= 0 ? i : i ^ 0x7fffffff;
}
__device__ inline float from_ordered_int(int i) {
    return __int_as_float(i >= 0 ? i : i ^ 0x7fffffff);
}

__device__ inline float half_area(float3 lo, float3 hi) {
    const float dx = hi.x - lo.x, dy = hi.y - lo.y, dz = hi.z - lo.z;
    return dx * dy + dy * dz + dz * dx;
}

__device__ inline uint3 build_triangle(const GpuBuildParams& p, unsigned t) {
    return p.indices ? p.indices[t] : make_uint3(3 * t, 3 * t + 1, 3 * t + 2);
}

__device__ inline bool triangle_in_range(const GpuBuildParams& p, uint3 v) {
    return v.x < p.vertex_count && v.y < p.vertex_count && v.z < p.vertex_count;
}

__device__ inline void triangle_box(const GpuBuildParams& p, unsigned t, float3& lo, float3& hi) {
    const uint3 v = build_triangle(p, t);
    if (!triangle_in_range(p, v)) {  // reported through kCounterBadIndex; keep going safely
        lo = hi = make_float3(0.0f, 0.0f, 0.0f);
        return;
    }
    const float3 a = p.positions[v.x], b = p.positions[v.y], c = p.positions[v.z];
    lo = fminf(a, fminf(b, c));
    hi = fmaxf(a, fmaxf(b, c));
}

/// Spreads the low 10 bits of x to every third bit (Karras 2012, "Thinking parallel III").
__device__ inline unsigned expand_bits(unsigned x) {
    x = (x * 0x00010001u) & 0xFF0000FFu;
    x = (x * 0x00000101u) & 0x0F00F00Fu;
    x = (x * 0x00000011u) & 0xC30C30C3u;
    x = (x * 0x00000005u) & 0x49249249u;
    return x;
}

__device__ inline unsigned quantize(float v) {
    return (unsigned)fminf(fmaxf(v * 1024.0f, 0.0f), 1023.0f);
}

__device__ inline float3 shfl3(float3 v, int lane) {
    return make_float3(__shfl_sync(kFullMask, v.x, lane), __shfl_sync(kFullMask, v.y, lane),
                       __shfl_sync(kFullMask, v.z, lane));
}
__device__ inline float3 shfl3_down(float3 v, int delta) {
    return make_float3(__shfl_down_sync(kFullMask, v.x, delta),
                       __shfl_down_sync(kFullMask, v.y, delta),
                       __shfl_down_sync(kFullMask, v.z, delta));
}

// ---- 1, 2: centroid bounds and Morton codes --------------------------------------------

__device__ inline void kernel_build_reset(GpuBuildParams p) {
    const unsigned i = threadIdx.x;
    if (i >= kCounterCount) return;
    unsigned v = 0;
    if (i == kCounterNextNode) v = p.triangle_count;
    if (i == kCounterRoot || i == kCounterBadIndex) v = kBuildInvalid;
    if (i == kCounterFault) v = kFaultNone;
    if (i >= kCounterBounds && i < kCounterBounds + 3) v = (unsigned)ordered_int(3.0e38f);
    if (i >= kCounterBounds + 3 && i < kCounterBounds + 6) v = (unsigned)ordered_int(-3.0e38f);
    p.counters[i] = v;
}

__device__ inline void kernel_build_bounds(GpuBuildParams p) {
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    float3 c = make_float3(3.0e38f, 3.0e38f, 3.0e38f),
           d = make_float3(-3.0e38f, -3.0e38f, -3.0e38f);
    if (i < p.triangle_count) {
        if (!triangle_in_range(p, build_triangle(p, i)))
            atomicMin(&p.counters[kCounterBadIndex], i);
        float3 lo, hi;
        triangle_box(p, i, lo, hi);
        c = d = 0.5f * (lo + hi);
        p.split_slots[i] = kBuildInvalid;
        p.clusters[i] = i;
    }
    for (int o = 16; o > 0; o >>= 1) {
        c = fminf(
            c, make_float3(__shfl_xor_sync(kFullMask, c.x, o), __shfl_xor_sync(kFullMask, c.y, o),
                           __shfl_xor_sync(kFullMask, c.z, o)));
        d = fmaxf(
            d, make_float3(__shfl_xor_sync(kFullMask, d.x, o), __shfl_xor_sync(kFullMask, d.y, o),
                           __shfl_xor_sync(kFullMask, d.z, o)));
    }
    if ((threadIdx.x & 31u) == 0) {
        int* b = reinterpret_cast<int*>(p.counters + kCounterBounds);
        atomicMin(b + 0, ordered_int(c.x)), atomicMin(b + 1, ordered_int(c.y));
        atomicMin(b + 2, ordered_int(c.z));
        atomicMax(b + 3, ordered_int(d.x)), atomicMax(b + 4, ordered_int(d.y));
        atomicMax(b + 5, ordered_int(d.z));
    }
}

__device__ inline void kernel_build_morton(GpuBuildParams p) {
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= p.triangle_count) return;
    const int* b = reinterpret_cast<const int*>(p.counters + kCounterBounds);
    const float3 lo =
        make_float3(from_ordered_int(b[0]), from_ordered_int(b[1]), from_ordered_int(b[2]));
    const float3 hi =
        make_float3(from_ordered_int(b[3]), from_ordered_int(b[4]), from_ordered_int(b[5]));
    float3 blo, bhi;
    triangle_box(p, i, blo, bhi);
    const float3 c = 0.5f * (blo + bhi);
#if LUCENT_MORTON_CUBE
    const float e = fmaxf(hi.x - lo.x, fmaxf(hi.y - lo.y, hi.z - lo.z));
    const float3 extent = make_float3(e, e, e);
#else
    const float3 extent = hi - lo;
#endif
    auto unit = [](float v, float l, float e) { return e > 0.0f ? (v - l) / e : 0.0f; };
    const unsigned x = quantize(unit(c.x, lo.x, extent.x));
    const unsigned y = quantize(unit(c.y, lo.y, extent.y));
    const unsigned z = quantize(unit(c.z, lo.z, extent.z));
    p.keys[i] = expand_bits(x) << 2 | expand_bits(y) << 1 | expand_bits(z);
    p.order[i] = i;
}

// ---- 3: the sort is radix_sort.cuh -------------------------------------------------------

// ---- 4: leaves ---------------------------------------------------------------------------

__device__ inline void kernel_build_leaves(GpuBuildParams p) {
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= p.triangle_count) return;
    float3 lo, hi;
    triangle_box(p, p.order[i], lo, hi);
    p.node_lo[i] = make_float4(lo.x, lo.y, lo.z, p.intersection_cost * half_area(lo, hi));
    p.node_hi[i] = make_float4(hi.x, hi.y, hi.z, __uint_as_float(1u));
    p.node_children[i] = make_int2(-1, -1);
    p.node_inner[i] = 0;
    p.node_parent[i] = kBuildInvalid;
}

// ---- 5: H-PLOC ---------------------------------------------------------------------------

/// Difference of the (code, index) keys of leaves i and i + 1: Apetrei's delta, ties in
/// the code broken by the index as in Karras 2012.
__device__ inline unsigned long long code_delta(const unsigned* keys, unsigned i) {
    return (unsigned long long)(keys[i] ^ keys[i + 1]) << 32 | (i ^ (i + 1));
}

/// The position of the k-th (from 0) set bit of mask, which has more than k set bits: the
/// largest p with k set bits below it (binary search on popcounts).
__device__ inline unsigned nth_set_bit(unsigned mask, unsigned k) {
    unsigned p = 0;
    for (unsigned step = 16; step > 0; step >>= 1)
        if ((unsigned)__popc(mask & ((1u << (p + step)) - 1u)) <= k) p += step;
    return p;
}

/// One cluster held by a lane during PLOC: its node and what a parent needs of it.
struct PlocCluster {
    unsigned node;
    float3 lo, hi;
    float cost;
    unsigned count, inner;
};

__device__ inline PlocCluster load_cluster(const GpuBuildParams& p, unsigned node) {
    // __ldcg: written by other multiprocessors, whose stores the L1 of this one never saw.
    const float4 lo = __ldcg(&p.node_lo[node]), hi = __ldcg(&p.node_hi[node]);
    PlocCluster c;
    c.node = node;
    c.lo = make_float3(lo.x, lo.y, lo.z);
    c.hi = make_float3(hi.x, hi.y, hi.z);
    c.cost = lo.w;
    c.count = __float_as_uint(hi.w);
    c.inner = __ldcg(&p.node_inner[node]);
    return c;
}

/// Reads the clusters of one half-range [begin, begin + size): at most kPlocClusters,
/// ended early by kBuildInvalid. Lane j gets the j-th; returns how many there are.
__device__ inline unsigned read_cluster_list(const GpuBuildParams& p, unsigned begin, unsigned size,
                                             unsigned lane, unsigned& node) {
    const unsigned window = size < (unsigned)kPlocClusters ? size : (unsigned)kPlocClusters;
    // Every lane loads an index inside the range: __ldcg is an asm statement the compiler
    // may issue unconditionally, so a guarded load must not point past the array.
    const unsigned at = begin + (lane < window ? lane : window - 1);
    node = __ldcg(&p.clusters[at]);
    if (lane >= window) node = kBuildInvalid;
    const unsigned ended = __ballot_sync(kFullMask, lane < window && node == kBuildInvalid);
    return ended ? (unsigned)(__ffs(ended) - 1) : window;
}

/// PLOC on the clusters of [left, right] (halves split at `split`), by the whole warp:
/// merges until at most kPlocClusters remain (1 when `final`), and stores them back at
/// clusters[left ...], ended by kBuildInvalid.
__device__ void ploc_merge(const GpuBuildParams& p, unsigned lane, unsigned left, unsigned split,
                           unsigned right, bool final) {
    unsigned node_left, node_right;
    const unsigned n_left = read_cluster_list(p, left, split - left, lane, node_left);
    const unsigned n_right = read_cluster_list(p, split, right - split + 1, lane, node_right);
    const unsigned from_right = __shfl_sync(kFullMask, node_right, (lane - n_left) & 31u);
    unsigned n = n_left + n_right;
    const unsigned my_node = lane < n_left ? node_left : lane < n ? from_right : kBuildInvalid;
    // Lanes past the clusters load the first one (the load is unconditional, see above).
    const unsigned first_node = __shfl_sync(kFullMask, my_node, 0);
    PlocCluster c = load_cluster(p, lane < n ? my_node : first_node);
    const unsigned target = final ? 1u : (unsigned)kPlocClusters;
    const unsigned below = (1u << lane) - 1u;
#ifdef LUCENT_BUILD_DEBUG
    if (lane == 0)
        printf("merge [%u %u %u] final %d: %u + %u clusters, first %u\n", left, split, right,
               (int) final, n_left, n_right, my_node);
#endif

    while (n > target) {
        // Nearest neighbour within kPlocRadius lanes on either side; the key packs the
        // union's area with the neighbour's lane, so ties pick the lowest lane and a
        // mutual pair always exists (the smallest key of all).
        unsigned best = kBuildInvalid;
        for (int o = 1; o <= kPlocRadius; ++o) {
            const float3 olo = shfl3_down(c.lo, o), ohi = shfl3_down(c.hi, o);
            const bool pair = lane + o < n;
            const unsigned area =
                __float_as_uint(half_area(fminf(c.lo, olo), fmaxf(c.hi, ohi))) & ~31u;
            if (pair) best = min(best, area | (lane + o));
            const unsigned mirrored =
                __shfl_up_sync(kFullMask, pair ? (area | lane) : kBuildInvalid, o);
            if (lane >= (unsigned)o) best = min(best, mirrored);
        }
        const unsigned nearest = best & 31u;
        // (The shuffle is outside the && on purpose: every lane of the mask must execute it.)
        const unsigned nearest_of_nearest = __shfl_sync(kFullMask, nearest, nearest);
        const bool mutual = lane < n && nearest_of_nearest == lane;
        const PlocCluster other = {__shfl_sync(kFullMask, c.node, nearest),
                                   shfl3(c.lo, nearest),
                                   shfl3(c.hi, nearest),
                                   __shfl_sync(kFullMask, c.cost, nearest),
                                   __shfl_sync(kFullMask, c.count, nearest),
                                   __shfl_sync(kFullMask, c.inner, nearest)};
        const bool create = mutual && lane < nearest;
        const unsigned creators = __ballot_sync(kFullMask, create);
        unsigned base = 0;
        if (lane == 0 && creators)
            base = atomicAdd(&p.counters[kCounterNextNode], __popc(creators));
        base = __shfl_sync(kFullMask, base, 0);
#ifdef LUCENT_BUILD_DEBUG
        if (lane == 0) printf("  n %u creators %08x base %u\n", n, creators, base);
#endif
        if (creators == 0 || base + __popc(creators) > 2 * p.triangle_count - 1) {
            if (lane == 0)
                atomicCAS(&p.counters[kCounterFault], kFaultNone,
                          creators == 0 ? kFaultNoMutualPair : kFaultNodeOverflow);
            return;
        }
        if (create) {
            const unsigned node = base + __popc(creators & below);
            const float3 lo = fminf(c.lo, other.lo), hi = fmaxf(c.hi, other.hi);
            const float a = half_area(lo, hi);
            const unsigned count = c.count + other.count;
            const float inner_cost = p.traversal_cost * a + c.cost + other.cost;
            const float leaf_cost = p.intersection_cost * (float)count * a;
            // The root stays an inner node (the layout's root is one).
            const bool root = final && n == 2;
            const bool leaf = !root && count <= p.max_leaf_size && leaf_cost <= inner_cost;
            c.cost = leaf ? leaf_cost : inner_cost;
            c.inner = leaf ? 0u : 1u + c.inner + other.inner;
            p.node_lo[node] = make_float4(lo.x, lo.y, lo.z, c.cost);
            p.node_hi[node] = make_float4(hi.x, hi.y, hi.z, __uint_as_float(count));
            p.node_children[node] = make_int2((int)c.node, (int)other.node);
            p.node_inner[node] = c.inner;
            p.node_parent[node] = kBuildInvalid;
            p.node_parent[c.node] = node;
            p.node_parent[other.node] = node;
            c.node = node, c.lo = lo, c.hi = hi, c.count = count;
        }
        // The higher lane of each merged pair gives up its cluster; the rest close ranks.
        const bool keep = lane < n && !(mutual && lane > nearest);
        const unsigned kept = __ballot_sync(kFullMask, keep);
        const unsigned n_kept = __popc(kept);
        const int source = lane < n_kept ? (int)nth_set_bit(kept, lane) : (int)lane;
        c.node = __shfl_sync(kFullMask, c.node, source);
        c.lo = shfl3(c.lo, source), c.hi = shfl3(c.hi, source);
        c.cost = __shfl_sync(kFullMask, c.cost, source);
        c.count = __shfl_sync(kFullMask, c.count, source);
        c.inner = __shfl_sync(kFullMask, c.inner, source);
        n = n_kept;
    }
    if (lane < n) p.clusters[left + lane] = c.node;
    if (lane == n && left + n <= right) p.clusters[left + n] = kBuildInvalid;
    if (final && lane == 0) p.counters[kCounterRoot] = c.node;
    // Every lane wrote nodes or clusters of this range: all of it must be visible before
    // the lane that owns the range hands it on (its exchange in lucent_build_hploc).
    __threadfence();
    __syncwarp();
}

/// One thread per leaf; a warp's lanes climb together and merge together (warp-wide code:
/// the grid is a whole number of warps, lanes past N only help).
__device__ inline void kernel_build_hploc(GpuBuildParams p) {
    const unsigned n = p.triangle_count;
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    const unsigned lane = threadIdx.x & 31u;
    unsigned left = i, right = i, split = 0;
    bool active = i < n;
    while (__ballot_sync(kFullMask, active)) {
        if (active) {
            unsigned previous;
            // Our range's parent splits on the side whose code difference is smaller.
            if (left == 0 ||
                (right != n - 1 && code_delta(p.keys, right) < code_delta(p.keys, left - 1))) {
                split = right + 1;  // we are the left child
                __threadfence();    // our clusters are visible before the exchange
                previous = atomicExch(&p.split_slots[right], left);
                if (previous != kBuildInvalid) right = previous;
            } else {
                split = left;  // we are the right child
                __threadfence();
                previous = atomicExch(&p.split_slots[left - 1], right);
                if (previous != kBuildInvalid) left = previous;
            }
            if (previous == kBuildInvalid)
                active = false;  // the first child to arrive stops; the second goes on
            else
                __threadfence();  // and sees what the first one wrote
        }
        const unsigned size = right - left + 1;
        const bool final = active && size == n;
        unsigned merges =
            __ballot_sync(kFullMask, active && (size > (unsigned)kPlocClusters || final));
        while (merges) {
            const int src = __ffs(merges) - 1;
            merges &= merges - 1;
            ploc_merge(p, lane, __shfl_sync(kFullMask, left, src),
                       __shfl_sync(kFullMask, split, src), __shfl_sync(kFullMask, right, src),
                       __shfl_sync(kFullMask, final, src));
        }
        if (final) active = false;
    }
}

// ---- 6: the layout -------------------------------------------------------------------------

__device__ inline float4 layout_box_xy(float4 lo, float4 hi) {
    return make_float4(lo.x, hi.x, lo.y, hi.y);
}

/// Writes the triangles of the subtree under `node` (emitted as one leaf) from `first` on,
/// left to right.
__device__ void write_leaf_triangles(const GpuBuildParams& p, unsigned node, unsigned first) {
    unsigned stack[2 * kGpuMaxLeafSize];
    int sp = 0;
    stack[sp++] = node;
    unsigned at = first;
    while (sp > 0) {
        const unsigned x = stack[--sp];
        if (at - first >= (unsigned)kGpuMaxLeafSize || sp + 2 > 2 * kGpuMaxLeafSize) {
            atomicCAS(&p.counters[kCounterFault], kFaultNone, kFaultLeafTooBig);
            return;
        }
        if (x < p.triangle_count) {
            const unsigned t = p.order[x];
            const uint3 v = build_triangle(p, t);
            const bool ok = triangle_in_range(p, v);
            const float3 a = ok ? p.positions[v.x] : make_float3(0, 0, 0);
            const float3 b = ok ? p.positions[v.y] : a, c = ok ? p.positions[v.z] : a;
            gpu_store_triangle(p.out_triangles, at, a, b, c);
            p.out_triangle_ids[at] = t;
            ++at;
        } else {
            const int2 ch = p.node_children[x];
            stack[sp++] = (unsigned)ch.y;
            stack[sp++] = (unsigned)ch.x;
        }
    }
}

__device__ inline unsigned node_count_of(const GpuBuildParams& p, unsigned node) {
    return __float_as_uint(p.node_hi[node].w);
}

/// One thread per internal node of the H-PLOC tree; those that become inner nodes of the
/// layout write one. A one-triangle mesh gets a root whose second box is empty.
__device__ inline void kernel_build_emit(GpuBuildParams p) {
    const unsigned n = p.triangle_count;
    const unsigned x = n + blockIdx.x * blockDim.x + threadIdx.x;
    const float4 empty_xy = make_float4(3.0e38f, -3.0e38f, 3.0e38f, -3.0e38f);
    if (n == 1) {
        if (x != n) return;
        const float4 lo = p.node_lo[0], hi = p.node_hi[0];
        p.out_nodes[0] = layout_box_xy(lo, hi);
        p.out_nodes[1] = empty_xy;
        p.out_nodes[2] = make_float4(lo.z, hi.z, 3.0e38f, -3.0e38f);
        const int leaf = gpu_make_leaf(0, 1);
        p.out_nodes[3] = make_float4(__int_as_float(leaf), __int_as_float(leaf), 0.0f, 0.0f);
        p.out_parents[0] = kBuildInvalid;
        write_leaf_triangles(p, 0, 0);
        p.counters[kCounterDepth] = 1;
        p.counters[kCounterInner] = 1;
        p.counters[kCounterSah] = __float_as_uint(
            lo.w /
            fmaxf(half_area(make_float3(lo.x, lo.y, lo.z), make_float3(hi.x, hi.y, hi.z)), 1e-30f));
        return;
    }
    if (x >= 2 * n - 1 || p.node_inner[x] == 0) return;
    // Our place in depth-first order: 1 past the parent for child 0, past the parent and all
    // of child 0's inner nodes for child 1; the triangles likewise.
    unsigned index = 0, first = 0, depth = 1;
    for (unsigned c = x, parent = p.node_parent[x]; parent != kBuildInvalid;
         c = parent, parent = p.node_parent[parent]) {
        if (p.node_inner[parent] == 0) return;  // inside a subtree that became one leaf
        const int2 ch = p.node_children[parent];
        if (c == (unsigned)ch.x) {
            index += 1;
        } else {
            index += 1 + p.node_inner[ch.x];
            first += node_count_of(p, ch.x);
        }
        if (++depth >= (unsigned)kGpuStackSize) {
            atomicCAS(&p.counters[kCounterFault], kFaultNone, kFaultDeepTree);
            return;
        }
    }
    if (index + p.node_inner[x] > p.triangle_count - 1) {  // past the last inner node
        atomicCAS(&p.counters[kCounterFault], kFaultNone, kFaultNodeOverflow);
        return;
    }
    const int2 ch = p.node_children[x];
    const unsigned c0 = (unsigned)ch.x, c1 = (unsigned)ch.y;
    const float4 lo0 = p.node_lo[c0], hi0 = p.node_hi[c0], lo1 = p.node_lo[c1], hi1 = p.node_hi[c1];
    float4* out = p.out_nodes + kGpuNodeFloat4s * index;
    out[0] = layout_box_xy(lo0, hi0);
    out[1] = layout_box_xy(lo1, hi1);
    out[2] = make_float4(lo0.z, hi0.z, lo1.z, hi1.z);
    const unsigned count0 = __float_as_uint(hi0.w), count1 = __float_as_uint(hi1.w);
    const unsigned index0 = index + 1, index1 = index + 1 + p.node_inner[c0];
    int ref0, ref1;
    if (p.node_inner[c0] == 0) {
        ref0 = gpu_make_leaf(first, count0);
        write_leaf_triangles(p, c0, first);
    } else {
        ref0 = (int)(kGpuNodeFloat4s * index0);
        p.out_parents[index0] = index << 1;
    }
    if (p.node_inner[c1] == 0) {
        ref1 = gpu_make_leaf(first + count0, count1);
        write_leaf_triangles(p, c1, first + count0);
    } else {
        ref1 = (int)(kGpuNodeFloat4s * index1);
        p.out_parents[index1] = index << 1 | 1u;
    }
    out[3] = make_float4(__int_as_float(ref0), __int_as_float(ref1), 0.0f, 0.0f);
    atomicMax(&p.counters[kCounterDepth], depth);
    if (index == 0) {
        p.out_parents[0] = kBuildInvalid;
        const float4 lo = p.node_lo[x], hi = p.node_hi[x];
        const float a = half_area(make_float3(lo.x, lo.y, lo.z), make_float3(hi.x, hi.y, hi.z));
        p.counters[kCounterSah] = __float_as_uint(a > 0.0f ? lo.w / a : lo.w);
        p.counters[kCounterInner] = p.node_inner[x];
    }
}

#endif  // LUCENT_GPU_CODE

}  // namespace lucent::gpu

#if LUCENT_GPU_CODE
// The entry points the host launches (extern "C": unmangled names for cuModuleGetFunction).
extern "C" __global__ void lucent_build_reset(lucent::gpu::GpuBuildParams p) {
    lucent::gpu::kernel_build_reset(p);
}
extern "C" __global__ void lucent_build_bounds(lucent::gpu::GpuBuildParams p) {
    lucent::gpu::kernel_build_bounds(p);
}
extern "C" __global__ void lucent_build_morton(lucent::gpu::GpuBuildParams p) {
    lucent::gpu::kernel_build_morton(p);
}
extern "C" __global__ void lucent_build_leaves(lucent::gpu::GpuBuildParams p) {
    lucent::gpu::kernel_build_leaves(p);
}
extern "C" __global__ void lucent_build_hploc(lucent::gpu::GpuBuildParams p) {
    lucent::gpu::kernel_build_hploc(p);
}
extern "C" __global__ void lucent_build_emit(lucent::gpu::GpuBuildParams p) {
    lucent::gpu::kernel_build_emit(p);
}
#endif  // LUCENT_GPU_CODE

// The GPU binned-SAH builder's helpers for both compilers (bvh_sah_build.cuh): ordered
// floats and atomics, boxes, bins and their sweep (the SAH of the host's builder), the
// decision of a node, and the steps of a per-block pass.
#pragma once

#include "lucent/device/platform.h"
#include "lucent/device/types.h"
#include "lucent_gpu/bvh_sah_params.cuh"

#if !LUCENT_GPU_CODE
#include <atomic>
#include <bit>
#include <cstring>
#endif

namespace lucent::gpu {

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
/// Atomic min and max of an int or an unsigned (CUDA's atomicMin / atomicMax overloads).
template <class T>
LUCENT_HD inline void sah_atomic_min(T* a, T v) {
#if LUCENT_GPU_CODE
    atomicMin(a, v);
#else
    std::atomic_ref<T> r(*a);
    T old = r.load();
    while (v < old && !r.compare_exchange_weak(old, v)) {
    }
#endif
}
template <class T>
LUCENT_HD inline void sah_atomic_max(T* a, T v) {
#if LUCENT_GPU_CODE
    atomicMax(a, v);
#else
    std::atomic_ref<T> r(*a);
    T old = r.load();
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

#if LUCENT_GPU_CODE
/// The same sweep by the 32 lanes of a warp, lane b holding bin b: the bins' counts and boxes
/// scanned both ways with shuffles, each lane pricing its plane, and the cheapest plane found
/// by a butterfly. One lane's sweep is two chains of 31 dependent steps, about 29 us for a
/// task on an H200 (ncu: the split pass took as long with one task as with a thousand, and the
/// small tasks' warps ran 5.7 of 32 lanes). Exactly the sequential sweep's result: counts
/// add and ordered boxes grow by min and max in any order to the same integers, each plane's
/// cost is the same expression of them, and ties go to the lowest plane, as the sequential
/// strict "<" keeps the first. Every lane of the warp must call it; each gets the result.
__device__ inline SahBest sah_sweep_axis_warp(const unsigned* axis, unsigned nb, unsigned lane) {
    constexpr unsigned kAll = 0xffffffffu;
    static_assert(kSahBins <= 32, "a lane per bin");
    unsigned count = 0;
    int box[6];
    sah_clear_box(box);
    if (lane < nb) {
        const unsigned* bin = axis + lane * kSahBinWords;
        count = bin[0];
        for (int c = 0; c < 6; ++c) box[c] = (int)bin[1 + c];
    }
    // Inclusive scans: bins 0..lane (prefix) and lane..31 (suffix; lanes past nb are empty).
    unsigned prefix_count = count, suffix_count = count;
    int prefix[6], suffix[6], other[6];
    for (int c = 0; c < 6; ++c) prefix[c] = suffix[c] = box[c];
    for (unsigned offset = 1; offset < 32; offset <<= 1) {
        const unsigned up = __shfl_up_sync(kAll, prefix_count, offset);
        for (int c = 0; c < 6; ++c) other[c] = __shfl_up_sync(kAll, prefix[c], offset);
        if (lane >= offset) {
            prefix_count += up;
            sah_accumulate(prefix, other);
        }
        const unsigned down = __shfl_down_sync(kAll, suffix_count, offset);
        for (int c = 0; c < 6; ++c) other[c] = __shfl_down_sync(kAll, suffix[c], offset);
        if (lane + offset < 32) {
            suffix_count += down;
            sah_accumulate(suffix, other);
        }
    }
    // Plane `lane` has bins 0..lane-1 on its left: the prefix of the lane below.
    const unsigned left_count = __shfl_up_sync(kAll, prefix_count, 1);
    int left[6];
    for (int c = 0; c < 6; ++c) left[c] = __shfl_up_sync(kAll, prefix[c], 1);
    SahBest best{3.402823e38f, 0, 0};
    if (lane >= 1 && lane < nb && left_count != 0 && suffix_count != 0) {
        float3 lo, hi, rlo, rhi;
        sah_box_of(left, lo, hi);
        sah_box_of(suffix, rlo, rhi);
        const float cost = sah_add(sah_mul(sah_half_area(lo, hi), (float)left_count),
                                   sah_mul(sah_half_area(rlo, rhi), (float)suffix_count));
        if (cost < best.cost) best = SahBest{cost, (int)lane, left_count};
    }
    for (unsigned offset = 16; offset > 0; offset >>= 1) {
        const float cost = __shfl_xor_sync(kAll, best.cost, offset);
        const int bin = __shfl_xor_sync(kAll, best.bin, offset);
        const unsigned left_of = __shfl_xor_sync(kAll, best.left_count, offset);
        // No plane (cost 3.4e38, bin 0) loses to any plane, and equal costs go to the lower.
        if (cost < best.cost || (cost == best.cost && bin < best.bin && bin > 0))
            best = SahBest{cost, bin, left_of};
    }
    return best;
}
#endif

/// Every axis's best plane into best[0..2], inside a sah_step of a warp's `threads`
/// (thread t). On the GPU the warp sweeps each axis together (sah_sweep_axis_warp); on the CPU
/// (the tests' emulation, a thread at a time) three threads sweep an axis each.
LUCENT_HD inline void sah_sweep_axes(const unsigned* bins, unsigned nb, SahBest* best, unsigned t,
                                     unsigned threads) {
#if LUCENT_GPU_CODE
    if (threads == kSahWarp) {
        for (unsigned k = 0; k < 3; ++k) {
            const SahBest axis_best = sah_sweep_axis_warp(bins + k * nb * kSahBinWords, nb, t);
            if (t == 0) best[k] = axis_best;
        }
        return;
    }
#endif
    (void)threads;
    if (t < 3) best[t] = sah_sweep_axis(bins + t * nb * kSahBinWords, nb);
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

}  // namespace lucent::gpu

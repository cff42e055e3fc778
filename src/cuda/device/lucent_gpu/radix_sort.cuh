// A stable LSD radix sort of 32-bit keys with 32-bit values, 8 bits a pass, for the GPU
// BVH builder (bvh_build.cuh): per-tile digit histograms, one exclusive scan, a stable
// scatter (Merrill and Grimshaw 2011, "High performance and scalable radix sorting", in its
// simplest reduce-then-scan form). The host launches the three kernels once per pass
// (src/cuda/accel/gpu_bvh_builder.cpp).
#pragma once

#include "lucent/device/platform.h"

namespace lucent::gpu {

constexpr int kSortThreads = 256;  // one thread per digit in the per-tile steps
constexpr int kSortItems = 8;      // keys per thread per tile
constexpr int kSortTile = kSortThreads * kSortItems;
constexpr int kSortScanThreads = 1024;

#if LUCENT_GPU_CODE

// Histograms are stored digit-major (hist[digit * tiles + tile]), so one exclusive scan of
// the whole array gives every tile its output offset per digit, and equal digits keep
// their tile order: the sort is stable, as LSD needs.

__device__ inline void kernel_radix_histogram(const unsigned* keys, unsigned n, unsigned shift,
                                              unsigned* hist, unsigned tiles) {
    __shared__ unsigned counts[256];
    counts[threadIdx.x] = 0;
    __syncthreads();
    const unsigned base = blockIdx.x * kSortTile;
    for (int k = 0; k < kSortItems; ++k) {
        const unsigned i = base + k * kSortThreads + threadIdx.x;
        if (i < n) atomicAdd(&counts[(keys[i] >> shift) & 255u], 1u);
    }
    __syncthreads();
    hist[threadIdx.x * tiles + blockIdx.x] = counts[threadIdx.x];
}

/// Exclusive scan of hist[0, count) in place, by one block.
__device__ inline void kernel_radix_scan(unsigned* hist, unsigned count) {
    __shared__ unsigned warp_sums[kSortScanThreads / 32];
    const unsigned per = (count + kSortScanThreads - 1) / kSortScanThreads;
    const unsigned begin = threadIdx.x * per;
    const unsigned end = begin + per < count ? begin + per : count;
    unsigned sum = 0;
    for (unsigned i = begin; i < end; ++i) sum += hist[i];
    // Block-wide exclusive scan of the per-thread sums.
    const unsigned lane = threadIdx.x & 31u, warp = threadIdx.x >> 5;
    unsigned inclusive = sum;
    for (int o = 1; o < 32; o <<= 1) {
        const unsigned v = __shfl_up_sync(0xffffffffu, inclusive, o);
        if (lane >= (unsigned)o) inclusive += v;
    }
    if (lane == 31) warp_sums[warp] = inclusive;
    __syncthreads();
    if (warp == 0) {
        unsigned w = warp_sums[lane], wi = w;
        for (int o = 1; o < 32; o <<= 1) {
            const unsigned v = __shfl_up_sync(0xffffffffu, wi, o);
            if (lane >= (unsigned)o) wi += v;
        }
        warp_sums[lane] = wi - w;
    }
    __syncthreads();
    unsigned run = warp_sums[warp] + inclusive - sum;
    for (unsigned i = begin; i < end; ++i) {
        const unsigned v = hist[i];
        hist[i] = run;
        run += v;
    }
}

/// Each warp ranks its 256 keys in input order (__match_any_sync groups equal digits), the
/// block adds the ranks of the warps before it, the scanned histogram gives the base.
__device__ inline void kernel_radix_scatter(const unsigned* keys_in, const unsigned* values_in,
                                            unsigned* keys_out, unsigned* values_out, unsigned n,
                                            unsigned shift, const unsigned* hist, unsigned tiles) {
    constexpr int kWarps = kSortThreads / 32;
    __shared__ unsigned warp_offset[kWarps][256];
    const unsigned lane = threadIdx.x & 31u, warp = threadIdx.x >> 5;
    for (int w = 0; w < kWarps; ++w) warp_offset[w][threadIdx.x] = 0;
    __syncthreads();
    const unsigned first = blockIdx.x * kSortTile + warp * (kSortItems * 32);
    const unsigned below = (1u << lane) - 1u;
    unsigned key[kSortItems], rank[kSortItems];
    for (int k = 0; k < kSortItems; ++k) {
        const unsigned i = first + k * 32 + lane;
        const bool valid = i < n;
        key[k] = valid ? keys_in[i] : 0u;
        const unsigned digit = valid ? (key[k] >> shift) & 255u : 256u;
        const unsigned peers = __match_any_sync(0xffffffffu, digit);
        if (valid) rank[k] = warp_offset[warp][digit] + __popc(peers & below);
        __syncwarp();
        if (valid && (__ffs(peers) - 1) == (int)lane) warp_offset[warp][digit] += __popc(peers);
        __syncwarp();
    }
    __syncthreads();
    {  // per digit: the tile's base, then the keys of the warps before
        const unsigned digit = threadIdx.x;
        unsigned run = hist[digit * tiles + blockIdx.x];
        for (int w = 0; w < kWarps; ++w) {
            const unsigned c = warp_offset[w][digit];
            warp_offset[w][digit] = run;
            run += c;
        }
    }
    __syncthreads();
    for (int k = 0; k < kSortItems; ++k) {
        const unsigned i = first + k * 32 + lane;
        if (i >= n) continue;
        const unsigned dest = warp_offset[warp][(key[k] >> shift) & 255u] + rank[k];
        keys_out[dest] = key[k];
        values_out[dest] = values_in[i];
    }
}

#endif  // LUCENT_GPU_CODE

}  // namespace lucent::gpu

#if LUCENT_GPU_CODE
// The entry points the host launches (extern "C": unmangled names for cuModuleGetFunction).
extern "C" __global__ void lucent_radix_histogram(const unsigned* keys, unsigned n, unsigned shift,
                                                  unsigned* hist, unsigned tiles) {
    lucent::gpu::kernel_radix_histogram(keys, n, shift, hist, tiles);
}
extern "C" __global__ void lucent_radix_scan(unsigned* hist, unsigned count) {
    lucent::gpu::kernel_radix_scan(hist, count);
}
extern "C" __global__ void lucent_radix_scatter(const unsigned* keys_in, const unsigned* values_in,
                                                unsigned* keys_out, unsigned* values_out,
                                                unsigned n, unsigned shift, const unsigned* hist,
                                                unsigned tiles) {
    lucent::gpu::kernel_radix_scatter(keys_in, values_in, keys_out, values_out, n, shift, hist,
                                      tiles);
}
#endif  // LUCENT_GPU_CODE

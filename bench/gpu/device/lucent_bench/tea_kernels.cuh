// The kernels of `bench tea --backend cuda`'s stream-ordered rows: TEA output written
// straight into device memory, one 1 MB launch after another on one stream, and an XOR fold
// that checks it afterwards (untimed) against the checksum of the engine's launches.
//
// Block b of the output is tea((b, 0), key, rounds): samples/tea/tea_programs.h's
// ray-generation programs, whose checksums these must equal (the bench compares them).
#pragma once

#include "lucent/device/tea.h"

/// Blocks first_block .. first_block + blocks - 1 into out[0 .. blocks - 1].
extern "C" __global__ void lucent_bench_tea(uint2* out, unsigned first_block, unsigned blocks,
                                            uint4 key, unsigned rounds) {
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < blocks) out[i] = lucent::tea(make_uint2(first_block + i, 0u), key, rounds);
}

/// *checksum ^= the XOR of both words of every block in words[0 .. count - 1]: one atomic
/// per thread block, after a warp shuffle and a shared-memory step.
extern "C" __global__ void lucent_bench_xor_fold(const uint2* words, unsigned long long count,
                                                 unsigned* checksum) {
    unsigned folded = 0;
    for (unsigned long long i = blockIdx.x * (unsigned long long)blockDim.x + threadIdx.x;
         i < count; i += (unsigned long long)gridDim.x * blockDim.x) {
        const uint2 w = words[i];
        folded ^= w.x ^ w.y;
    }
    for (int offset = 16; offset > 0; offset /= 2)
        folded ^= __shfl_xor_sync(0xffffffffu, folded, offset);
    __shared__ unsigned warps[32];
    if ((threadIdx.x & 31) == 0) warps[threadIdx.x / 32] = folded;
    __syncthreads();
    if (threadIdx.x == 0) {
        unsigned all = 0;
        for (unsigned w = 0; w < blockDim.x / 32; ++w) all ^= warps[w];
        atomicXor(checksum, all);
    }
}

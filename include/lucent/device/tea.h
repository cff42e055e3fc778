// TEA, the Tiny Encryption Algorithm (Wheeler and Needham 1994), as a pseudorandom number
// generator (Zafar et al. 2010; Sebald, §3.2), and per-device keys (Sebald, Fig. 4).
// Device code: compiles with g++, nvcc and NVRTC.
#pragma once

#include "lucent/device/vector_math.h"

namespace lucent {

constexpr unsigned kTeaDelta = 0x9E3779B9u;

/// One TEA round on (v0, v1) with key k; `sum` is the round's multiple of delta.
LUCENT_HD inline void tea_round(unsigned& v0, unsigned& v1, uint4 k, unsigned sum) {
    v0 += ((v1 << 4) + k.x) ^ (v1 + sum) ^ ((v1 >> 5) + k.y);
    v1 += ((v0 << 4) + k.z) ^ (v0 + sum) ^ ((v0 >> 5) + k.w);
}

/// TEA encryption of the block v with key k in `Rounds` rounds, unrolled. As its authors
/// define it, `sum` grows by delta before every round: the seed's Figure 3 omits that step,
/// which would leave every round the same function. 32 rounds is the cipher.
template <unsigned Rounds>
LUCENT_HD inline uint2 tea(uint2 v, uint4 k) {
    unsigned v0 = v.x, v1 = v.y, sum = 0;
#if LUCENT_CUDA_TYPES
#pragma unroll
#endif
    for (unsigned i = 0; i < Rounds; ++i) {
        sum += kTeaDelta;
        tea_round(v0, v1, k, sum);
    }
    return make_uint2(v0, v1);
}

/// TEA with a round count chosen at run time (the CLI, tests and benchmarks).
LUCENT_HD inline uint2 tea(uint2 v, uint4 k, unsigned rounds) {
    unsigned v0 = v.x, v1 = v.y, sum = 0;
    for (unsigned i = 0; i < rounds; ++i) {
        sum += kTeaDelta;
        tea_round(v0, v1, k, sum);
    }
    return make_uint2(v0, v1);
}

/// Sebald's Figure 4: a device-unique key from an arbitrary initial key `ik` and the pair
/// d = (device identifier, seed), with 16-round TEA:
///   rv.yw = tea(d, ik); rv.xz = ik.yw; rv.xz = tea(d, rv).
LUCENT_HD inline uint4 generate_tea_key(uint4 ik, uint2 d) {
    uint4 rv;
    uint2 first = tea<16>(d, ik);
    rv.y = first.x;
    rv.w = first.y;
    rv.x = ik.y;
    rv.z = ik.w;
    uint2 second = tea<16>(d, rv);
    rv.x = second.x;
    rv.z = second.y;
    return rv;
}

/// The key Zafar et al. fixed in their generator (the "original" of Sebald's Table 2).
LUCENT_HD inline uint4 zafar_tea_key() {
    return make_uint4(0xA341316Cu, 0xC8013EA4u, 0xAD90777Du, 0x7E95761Eu);
}

/// A uniform float in [0, 1) from the top 24 bits of a TEA output word.
LUCENT_HD inline float tea_unit_float(unsigned word) {
    return float(word >> 8) * (1.0f / 16777216.0f);
}

}  // namespace lucent

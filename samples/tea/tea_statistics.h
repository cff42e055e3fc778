// Statistics of the TEA generator's output stream (the tests of `ent`): how far the bits
// are from balanced, the chi-square of the byte histogram, and the serial correlation of
// successive bytes. Seed: Sebald §3.2 (rounds against quality), Zafar et al. 2010.
#pragma once

#include <cstdint>

#include "lucent/device/vector_math.h"

namespace lucent::samples {

struct TeaStatistics {
    unsigned rounds = 0;
    uint64_t bytes = 0;
    double ones_fraction = 0;       // of all output bits; 0.5 expected
    double bit_balance_z = 0;       // (ones - n/2) / sqrt(n/4): |z| < 5 expected
    double byte_chi_square = 0;     // 256 bins, 255 degrees of freedom: about 255 expected
    double chi_square_p = 0;        // upper-tail probability of that chi-square
    double serial_correlation = 0;  // of successive bytes: |r| < 5 / sqrt(bytes) expected

    /// Whether every statistic is inside the bounds above (chi-square p in [1e-4, 1 - 1e-4]).
    bool passes() const;
};

/// Encrypts the counter blocks (i, stream) for i < blocks with `key` in `rounds` rounds and
/// measures the bytes of the output (8 per block).
TeaStatistics measure_tea(unsigned rounds, uint4 key, uint64_t blocks, unsigned stream = 0);

}  // namespace lucent::samples

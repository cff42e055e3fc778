#include "samples/tea/tea_statistics.h"

#include <bit>
#include <cmath>
#include <vector>

#include "lucent/device/tea.h"

namespace lucent::samples {

namespace {
/// Upper-tail probability of a chi-square with k degrees of freedom, by the Wilson–Hilferty
/// cube-root normal approximation (accurate to about 1e-3 for k = 255).
double chi_square_upper_tail(double x, double k) {
    double z = (std::cbrt(x / k) - (1.0 - 2.0 / (9.0 * k))) / std::sqrt(2.0 / (9.0 * k));
    return 0.5 * std::erfc(z / std::sqrt(2.0));
}
}  // namespace

bool TeaStatistics::passes() const {
    return std::fabs(bit_balance_z) < 5.0 && chi_square_p > 1e-4 && chi_square_p < 1.0 - 1e-4 &&
           std::fabs(serial_correlation) < 5.0 / std::sqrt(double(bytes));
}

TeaStatistics measure_tea(unsigned rounds, uint4 key, uint64_t blocks, unsigned stream) {
    std::vector<uint64_t> histogram(256, 0);
    uint64_t ones = 0;
    // Serial correlation (ent): sum of products of each byte with the next, cyclically.
    double sum = 0, sum_squares = 0, sum_products = 0;
    unsigned first = 0, previous = 0;
    bool have_previous = false;
    for (uint64_t i = 0; i < blocks; ++i) {
        uint2 out = tea(make_uint2(unsigned(i), stream), key, rounds);
        for (unsigned word : {out.x, out.y}) {
            ones += unsigned(std::popcount(word));
            for (int b = 0; b < 4; ++b) {
                unsigned byte = (word >> (8 * b)) & 0xffu;
                ++histogram[byte];
                sum += byte;
                sum_squares += double(byte) * byte;
                if (have_previous)
                    sum_products += double(previous) * byte;
                else
                    first = byte;
                previous = byte;
                have_previous = true;
            }
        }
    }
    sum_products += double(previous) * first;

    TeaStatistics s;
    s.rounds = rounds;
    s.bytes = blocks * 8;
    const double n = double(s.bytes), bits = n * 8;
    s.ones_fraction = double(ones) / bits;
    s.bit_balance_z = (double(ones) - bits / 2) / std::sqrt(bits / 4);
    const double expected = n / 256;
    for (uint64_t count : histogram)
        s.byte_chi_square += (count - expected) * (count - expected) / expected;
    s.chi_square_p = chi_square_upper_tail(s.byte_chi_square, 255);
    const double denominator = n * sum_squares - sum * sum;
    s.serial_correlation = denominator == 0 ? 1.0 : (n * sum_products - sum * sum) / denominator;
    return s;
}

}  // namespace lucent::samples

// TEA noise images (Sebald Figures 5-7): statistics of white and gradient noise, and the
// spectrum as a detector of structure in the generator.
#include <gtest/gtest.h>

#include <cmath>

#include "lucent/device/noise.h"
#include "lucent/device/tea.h"
#include "lucent/error.h"
#include "samples/tea/tea_noise.h"

namespace {

using lucent::samples::gradient_noise;
using lucent::samples::noise_spectrum;
using lucent::samples::white_noise;

TEST(TeaNoise, WhiteNoiseIsUniformOnTheUnitInterval) {
    auto image = white_noise(64, 64, 4, lucent::zafar_tea_key());
    double sum = 0, squares = 0;
    for (const float3& p : image.pixels) {
        ASSERT_GE(p.x, 0.0f);
        ASSERT_LT(p.x, 1.0f);
        sum += p.x;
        squares += double(p.x) * p.x;
    }
    const double n = double(image.pixels.size()), mean = sum / n;
    EXPECT_NEAR(mean, 0.5, 0.02);  // 4.4 sigma for 4096 samples
    EXPECT_NEAR(squares / n - mean * mean, 1.0 / 12, 0.01);
}

TEST(TeaNoise, GradientNoiseIsSmoothAndCentred) {
    auto image = gradient_noise(256, 256, 32, 4, lucent::zafar_tea_key());
    double sum = 0;
    float largest_step = 0;
    for (unsigned y = 0; y < 256; ++y)
        for (unsigned x = 0; x < 256; ++x) {
            float v = image.pixels[y * 256 + x].x;
            ASSERT_GE(v, 0.0f);
            ASSERT_LE(v, 1.0f);
            sum += v;
            if (x > 0)
                largest_step =
                    std::max(largest_step, std::fabs(v - image.pixels[y * 256 + x - 1].x));
        }
    EXPECT_NEAR(sum / (256.0 * 256.0), 0.5, 0.05);
    EXPECT_LT(largest_step, 0.1f) << "one octave over 32-pixel cells changes slowly";
}

/// Correlation of horizontally neighbouring pixels, and the variance of the row means over
/// what independent uniform pixels give (1): the streaks of issue 21 item 6.
struct Streaks {
    double neighbour_correlation, row_mean_ratio;
};
Streaks streaks(const lucent::scene::Image& image) {
    const unsigned w = image.width, h = image.height;
    double mean = 0;
    for (const float3& p : image.pixels) mean += p.x;
    mean /= double(image.pixels.size());
    double products = 0, squares = 0, row_means = 0;
    for (unsigned y = 0; y < h; ++y) {
        double row = 0;
        for (unsigned x = 0; x < w; ++x) {
            const double a = image.pixels[y * w + x].x - mean;
            squares += a * a;
            row += a;
            if (x + 1 < w) products += a * (image.pixels[y * w + x + 1].x - mean);
        }
        row_means += (row / w) * (row / w);
    }
    return {products / (double(h) * (w - 1)) / (squares / (double(w) * h)),
            row_means / h * w * 12.0};
}

TEST(TeaNoise, FourRoundWhiteNoiseHasNoStreaks) {
    // Sebald's Figure 5: 4 rounds look random. The top 24 bits of v0 (what Lucent read
    // before) correlate neighbours by 0.44 and spread the row means 11x; the low 24 bits of
    // v1 do neither (docs/tea-rounds.md, 0.001 and 1.0 there).
    const uint4 key = lucent::zafar_tea_key();
    for (unsigned rounds : {4u, 8u}) {
        const Streaks s = streaks(white_noise(256, 256, rounds, key));
        EXPECT_LT(std::fabs(s.neighbour_correlation), 0.03) << rounds << " rounds";
        EXPECT_LT(s.row_mean_ratio, 1.5) << rounds << " rounds";
    }
    lucent::scene::Image old = white_noise(256, 256, 4, key);
    for (unsigned i = 0; i < old.pixels.size(); ++i)
        old.pixels[i] =
            make_float3(lucent::tea_unit_float(lucent::tea(make_uint2(i, 0), key, 4).x));
    const Streaks s = streaks(old);
    EXPECT_GT(s.neighbour_correlation, 0.3) << "the old reading streaks (the test's premise)";
    EXPECT_GT(s.row_mean_ratio, 5.0);
}

TEST(TeaNoise, FourRoundLatticeGradientsAreIndependentOfTheirNeighbours) {
    // Figure 6's banding: at 4 rounds, gradients drawn from the top bits of v0 at (ix, iy)
    // and (ix + 1, iy) point the same way on average (mean dot product 0.54 here).
    double dots = 0;
    unsigned n = 0;
    for (int y = -64; y < 64; ++y)
        for (int x = -64; x < 63; ++x, ++n) {
            const float2 a = lucent::tea_lattice_gradient(x, y, lucent::zafar_tea_key(), 4);
            const float2 b = lucent::tea_lattice_gradient(x + 1, y, lucent::zafar_tea_key(), 4);
            dots += a.x * b.x + a.y * b.y;
        }
    EXPECT_LT(std::fabs(dots / n), 0.03);  // sd 0.006 for 16256 independent pairs
}

#if LUCENT_HAVE_FFTW
/// Mean of the (log, normalised) spectrum over a column band around zero x-frequency
/// against the mean over everything else.
double centre_column_excess(const lucent::scene::Image& s) {
    double centre = 0, rest = 0;
    size_t nc = 0, nr = 0;
    for (unsigned y = 0; y < s.height; ++y)
        for (unsigned x = 0; x < s.width; ++x) {
            bool in = std::abs(int(x) - int(s.width / 2)) <= 2;
            (in ? centre : rest) += s.pixels[y * s.width + x].x;
            ++(in ? nc : nr);
        }
    return (centre / nc) / (rest / nr);
}

TEST(TeaNoise, SpectrumIsFlatWithEnoughRoundsAndShowsStructureWithFew) {
    // 16 rounds and, as in Figure 7, 4: no frequency stands out (reading the top bits of
    // v0, 4 rounds gave 1.31 here). 3 rounds over counter blocks: the rows differ in their
    // mean, a bright line at zero x-frequency (what Figure 7's tool is for).
    for (unsigned rounds : {4u, 16u})
        EXPECT_NEAR(centre_column_excess(noise_spectrum(256, rounds, lucent::zafar_tea_key())), 1.0,
                    0.02)
            << rounds << " rounds";
    auto few = noise_spectrum(256, 3, lucent::zafar_tea_key());
    EXPECT_GT(centre_column_excess(few), 1.03);
}
#else
TEST(TeaNoise, SpectrumNeedsFftw) {
    EXPECT_THROW(noise_spectrum(64, 4, lucent::zafar_tea_key()), lucent::Error);
}
#endif

}  // namespace

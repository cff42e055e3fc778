// TEA noise images (Sebald Figures 5-7): statistics of white and gradient noise, and the
// spectrum as a detector of structure in the generator.
#include <gtest/gtest.h>

#include <cmath>

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
    // 16 rounds: no frequency stands out. 4 rounds over counter blocks: the rows differ in
    // their mean, a bright line at zero x-frequency (what Figure 7's tool is for).
    auto flat = noise_spectrum(256, 16, lucent::zafar_tea_key());
    EXPECT_NEAR(centre_column_excess(flat), 1.0, 0.02);
    auto few = noise_spectrum(256, 4, lucent::zafar_tea_key());
    EXPECT_GT(centre_column_excess(few), 1.03);
}
#else
TEST(TeaNoise, SpectrumNeedsFftw) {
    EXPECT_THROW(noise_spectrum(64, 4, lucent::zafar_tea_key()), lucent::Error);
}
#endif

}  // namespace

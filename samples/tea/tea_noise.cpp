#include "samples/tea/tea_noise.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "lucent/device/noise.h"
#include "lucent/device/tea.h"
#include "lucent/error.h"

#if LUCENT_HAVE_FFTW
#include <fftw3.h>
#endif

namespace lucent::samples {

namespace {
scene::Image gray_image(unsigned width, unsigned height) {
    scene::Image image;
    image.width = width;
    image.height = height;
    image.pixels.resize(size_t(width) * height);
    return image;
}
}  // namespace

scene::Image white_noise(unsigned width, unsigned height, unsigned rounds, uint4 key) {
    scene::Image image = gray_image(width, height);
    for (unsigned i = 0; i < image.pixels.size(); ++i)
        image.pixels[i] = make_float3(tea_noise_unit(tea(make_uint2(i, 0), key, rounds)));
    return image;
}

scene::Image gradient_noise(unsigned width, unsigned height, unsigned cell, unsigned rounds,
                            uint4 key) {
    scene::Image image = gray_image(width, height);
    GradientCell corners;
    for (unsigned y = 0; y < height; ++y)
        for (unsigned x = 0; x < width; ++x)
            image.pixels[size_t(y) * width + x] = make_float3(tea_gradient_noise(
                (x + 0.5f) / float(cell), (y + 0.5f) / float(cell), key, rounds, corners));
    return image;
}

scene::Image noise_spectrum(unsigned size, unsigned rounds, uint4 key) {
#if LUCENT_HAVE_FFTW
    scene::Image noise = white_noise(size, size, rounds, key);
    const unsigned half = size / 2 + 1;
    std::vector<float> in(size_t(size) * size);
    for (size_t i = 0; i < in.size(); ++i) in[i] = noise.pixels[i].x - 0.5f;  // no DC spike
    fftwf_complex* out = fftwf_alloc_complex(size_t(size) * half);
    fftwf_plan plan = fftwf_plan_dft_r2c_2d(int(size), int(size), in.data(), out, FFTW_ESTIMATE);
    fftwf_execute(plan);
    // Log power, centred (frequency 0 in the middle); the r2c half mirrors the other.
    scene::Image image = gray_image(size, size);
    std::vector<float> power(size_t(size) * size);
    for (unsigned y = 0; y < size; ++y)
        for (unsigned x = 0; x < size; ++x) {
            unsigned fx = (x + size / 2) % size, fy = (y + size / 2) % size;
            unsigned cx = fx < half ? fx : size - fx, cy = fx < half ? fy : (size - fy) % size;
            const fftwf_complex& c = out[size_t(cy) * half + cx];
            power[size_t(y) * size + x] = std::log1p(c[0] * c[0] + c[1] * c[1]);
        }
    fftwf_destroy_plan(plan);
    fftwf_free(out);
    float top = *std::max_element(power.begin(), power.end());
    for (size_t i = 0; i < power.size(); ++i)
        image.pixels[i] = make_float3(top > 0 ? power[i] / top : 0);
    return image;
#else
    (void)size, (void)rounds, (void)key;
    throw Error("noise spectrum: this build has no FFTW (install libfftw3-dev and reconfigure)");
#endif
}

}  // namespace lucent::samples

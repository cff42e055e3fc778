#include "samples/tea/tea_noise.h"

#include <algorithm>
#include <cmath>
#include <vector>

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

float quintic(float t) {
    return t * t * t * (t * (t * 6 - 15) + 10);
}
}  // namespace

scene::Image white_noise(unsigned width, unsigned height, unsigned rounds, uint4 key) {
    scene::Image image = gray_image(width, height);
    for (unsigned i = 0; i < image.pixels.size(); ++i)
        image.pixels[i] = make_float3(tea_unit_float(tea(make_uint2(i, 0), key, rounds).x));
    return image;
}

scene::Image gradient_noise(unsigned width, unsigned height, unsigned cell, unsigned rounds,
                            uint4 key) {
    scene::Image image = gray_image(width, height);
    auto gradient = [&](int ix, int iy) {
        float angle =
            6.2831853f * tea_unit_float(tea(make_uint2(unsigned(ix), unsigned(iy)), key, rounds).x);
        return make_float2(std::cos(angle), std::sin(angle));
    };
    for (unsigned y = 0; y < height; ++y)
        for (unsigned x = 0; x < width; ++x) {
            float fx = (x + 0.5f) / float(cell), fy = (y + 0.5f) / float(cell);
            int ix = int(std::floor(fx)), iy = int(std::floor(fy));
            float tx = fx - ix, ty = fy - iy;
            // Dot products of the corner gradients with the offsets to the corners.
            float n00 = dot(gradient(ix, iy), make_float2(tx, ty));
            float n10 = dot(gradient(ix + 1, iy), make_float2(tx - 1, ty));
            float n01 = dot(gradient(ix, iy + 1), make_float2(tx, ty - 1));
            float n11 = dot(gradient(ix + 1, iy + 1), make_float2(tx - 1, ty - 1));
            float u = quintic(tx), v = quintic(ty);
            float n = lerpf(lerpf(n00, n10, u), lerpf(n01, n11, u), v);  // in [-0.71, 0.71]
            image.pixels[size_t(y) * width + x] = make_float3(clampf(0.5f + n * 0.70710678f, 0, 1));
        }
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

// 8-bit sRGB display frames on the GPU (Context::display_frame on the CUDA backend): each
// linear float4 pixel of a launch's output becomes RGBA8 by the host's own threshold table
// (lucent::srgb8_thresholds), so the codes equal the CPU's bit for bit. Launched by
// src/cuda/interop/display_frame.cpp.
#pragma once

#include "lucent/device/platform.h"
#include "lucent/device/types.h"

namespace lucent::gpu {

constexpr unsigned kSrgbThresholds = 255;
constexpr unsigned kDisplayThreads = 256;

#if LUCENT_GPU_CODE

/// The number of thresholds `v` reaches (NaN reaches none): its 8-bit sRGB code.
__device__ inline unsigned srgb8_code(const float* t, float v) {
    unsigned k = 0;
#pragma unroll
    for (unsigned step = 128; step > 0; step >>= 1)
        if (k + step <= kSrgbThresholds && v >= t[k + step - 1]) k += step;
    return k;
}

extern "C" __global__ void __launch_bounds__(kDisplayThreads)
    lucent_display_srgb8(const float4* __restrict__ linear, unsigned* __restrict__ rgba,
                         unsigned count, const float* __restrict__ thresholds) {
    __shared__ float t[kSrgbThresholds];
    for (unsigned i = threadIdx.x; i < kSrgbThresholds; i += blockDim.x) t[i] = thresholds[i];
    __syncthreads();
    for (unsigned i = blockIdx.x * blockDim.x + threadIdx.x; i < count;
         i += gridDim.x * blockDim.x) {
        const float4 p = linear[i];
        // Bytes R, G, B, A in memory (little-endian), as OpenGL's GL_RGBA8 reads them.
        rgba[i] = srgb8_code(t, p.x) | srgb8_code(t, p.y) << 8 | srgb8_code(t, p.z) << 16 |
                  0xff000000u;
    }
}

/// Copies a frame's pixels into an OpenGL texture's CUDA array (GlTexture::copy_from), one
/// thread per pixel through a surface: the copy engine's 2D copy into the array's tiled
/// layout measured 24 GB/s (0.34 ms at 1920x1080 on an H200), a kernel runs at memory speed.
extern "C" __global__ void lucent_display_to_surface(const unsigned* __restrict__ rgba,
                                                     unsigned long long surface, unsigned width,
                                                     unsigned height) {
    const unsigned x = blockIdx.x * blockDim.x + threadIdx.x;
    const unsigned y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= width || y >= height) return;
    // sust: a 32-bit store at byte column 4x of row y (surf2Dwrite without the runtime headers).
    asm volatile("sust.b.2d.b32.trap [%0, {%1, %2}], {%3};" ::"l"(surface), "r"(x * 4), "r"(y),
                 "r"(rgba[size_t(y) * width + x])
                 : "memory");
}

#endif  // LUCENT_GPU_CODE

}  // namespace lucent::gpu

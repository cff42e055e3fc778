// Noise from TEA hashes (Sebald §3.2, Figures 5-7): white noise, single-octave gradient
// noise, and the power spectrum of a patch, as images.
#pragma once

#include "lucent/device/vector_math.h"
#include "scene/image_io.h"

namespace lucent::samples {

/// Each pixel an independent uniform value: TEA of (pixel index, 0) with `rounds` rounds,
/// read by tea_noise_unit (lucent/device/noise.h).
scene::Image white_noise(unsigned width, unsigned height, unsigned rounds, uint4 key);

/// One octave of 2D gradient noise (Perlin 2002, quintic fade) on a lattice of `cell`
/// pixels, with unit gradients drawn by TEA at each lattice point; values mapped to [0, 1].
scene::Image gradient_noise(unsigned width, unsigned height, unsigned cell, unsigned rounds,
                            uint4 key);

/// The centred log power spectrum of white noise of size x size (FFTW), scaled to [0, 1]:
/// structure in the generator shows as lines or spots, good noise as an even field.
/// Throws lucent::Error when this build has no FFTW.
scene::Image noise_spectrum(unsigned size, unsigned rounds, uint4 key);

}  // namespace lucent::samples

// Gradient noise from TEA hashes (Perlin 1985, with the quintic fade of Perlin 2002; TEA as
// its hash after Zafar et al. 2010 and Sebald, §3.2). Device code: g++, nvcc and NVRTC.
#pragma once

#include "lucent/device/tea.h"
#include "lucent/device/vector_math.h"

namespace lucent {

/// A uniform float in [0, 1) from a TEA block whose input was a small counter (a pixel index,
/// a lattice point): the low 24 bits of v1, the word TEA's last half-round writes. A change
/// in the counter's low bits climbs the word through TEA's << 4 and its carries, so after
/// few rounds the top bits are the last to be mixed: at 4 rounds the top bits of v0 (what
/// tea_unit_float reads) still streak along the counter, horizontally neighbouring pixels
/// correlated by 0.44, where these bits are not (docs/tea-rounds.md).
LUCENT_HD inline float tea_noise_unit(uint2 block) {
    return float(block.y & 0xFFFFFFu) * (1.0f / 16777216.0f);
}

/// The unit gradient TEA draws at lattice point (ix, iy).
LUCENT_HD inline float2 tea_lattice_gradient(int ix, int iy, uint4 key, unsigned rounds) {
    const float angle =
        6.2831853f * tea_noise_unit(tea(make_uint2(unsigned(ix), unsigned(iy)), key, rounds));
    return make_float2(cosf(angle), sinf(angle));
}

LUCENT_HD inline float quintic_fade(float t) {
    return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f);
}

/// The four corner gradients of a lattice cell: what a march along a ray can keep while it
/// stays in one cell (the noise of the fog sample varies in x and z only).
struct GradientCell {
    int ix = 0x7fffffff, iy = 0x7fffffff;  // no cell yet
    float2 g00 = make_float2(0.0f, 0.0f), g10 = g00, g01 = g00, g11 = g00;

    LUCENT_HD void fetch(int x, int y, uint4 key, unsigned rounds) {
        if (x == ix && y == iy) return;
        ix = x;
        iy = y;
        g00 = tea_lattice_gradient(x, y, key, rounds);
        g10 = tea_lattice_gradient(x + 1, y, key, rounds);
        g01 = tea_lattice_gradient(x, y + 1, key, rounds);
        g11 = tea_lattice_gradient(x + 1, y + 1, key, rounds);
    }
};

/// The noise inside a fetched cell at (tx, ty) in [0, 1)^2 from its corner (ix, iy), mapped
/// to [0, 1]: the corner gradients dotted with the offsets to the corners, blended by the
/// quintic fade.
LUCENT_HD inline float gradient_noise_in_cell(const GradientCell& c, float tx, float ty) {
    const float n00 = dot(c.g00, make_float2(tx, ty));
    const float n10 = dot(c.g10, make_float2(tx - 1.0f, ty));
    const float n01 = dot(c.g01, make_float2(tx, ty - 1.0f));
    const float n11 = dot(c.g11, make_float2(tx - 1.0f, ty - 1.0f));
    const float u = quintic_fade(tx), v = quintic_fade(ty);
    const float n = lerpf(lerpf(n00, n10, u), lerpf(n01, n11, u), v);  // in [-0.71, 0.71]
    return clampf(0.5f + n * 0.70710678f, 0.0f, 1.0f);
}

/// One octave of gradient noise at (x, y), in lattice units, mapped to [0, 1]; `cell` keeps
/// the last cell's gradients between calls.
LUCENT_HD inline float tea_gradient_noise(float x, float y, uint4 key, unsigned rounds,
                                          GradientCell& cell) {
    const float fx = floorf(x), fy = floorf(y);
    cell.fetch(int(fx), int(fy), key, rounds);
    return gradient_noise_in_cell(cell, x - fx, y - fy);
}

LUCENT_HD inline float tea_gradient_noise(float x, float y, uint4 key, unsigned rounds) {
    GradientCell cell;
    return tea_gradient_noise(x, y, key, rounds, cell);
}

}  // namespace lucent

// The order in which `lucent bench rays --backend cuda` stores its rays: 8 x 4 pixel
// tiles, so that the 32 rays of a warp start from a compact patch of the image rather than
// a 32-pixel strip of a row (coherent rays visit the same nodes: Aila and Laine 2009,
// Sec. 5, measure how traversal speed falls with incoherence). Host and device code.
#pragma once

#include "lucent/device/platform.h"

namespace lucent::gpu {

/// The pixel (y * width + x) of ray r when rays are ordered by bands of 4 rows, each band
/// cut into blocks of 8 columns (narrower blocks at the right and bottom edges).
LUCENT_HD inline unsigned gpu_tiled_pixel(unsigned r, unsigned width, unsigned height) {
    const unsigned y0 = r / (4u * width) * 4u;
    const unsigned bh = height - y0 < 4u ? height - y0 : 4u;
    const unsigned local = r - y0 * width;
    const unsigned block = local / (8u * bh);
    const unsigned x0 = block * 8u;
    const unsigned bw = width - x0 < 8u ? width - x0 : 8u;
    const unsigned rem = local - block * 8u * bh;
    return (y0 + rem / bw) * width + x0 + rem % bw;
}

}  // namespace lucent::gpu

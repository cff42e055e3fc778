// Which device slot a launch index belongs to, for the per-device TEA keys (device API
// device_tea_key()). Device code: compiles with g++, nvcc and NVRTC.
#pragma once

#include "lucent/device/vector_math.h"

namespace lucent {

/// Launch indices come in tiles (8x8 over the grid's rows, row = z * height + y; 64 indices
/// in a one-row launch), dealt to the `slots` devices of the Context's list in turn. The
/// slot is fixed by the index alone, not by which device happened to run it: with dynamic
/// load balancing a run stays reproducible given the seed and the device list.
LUCENT_HD inline unsigned device_slot_of(uint3 index, uint3 size, unsigned slots) {
    if (slots <= 1) return 0;
    const bool one_row = size.y == 1 && size.z == 1;
    if (one_row) return (index.x / 64u) % slots;
    const unsigned tiles_x = (size.x + 7u) / 8u;
    const unsigned long long row = (unsigned long long)index.z * size.y + index.y;
    const unsigned long long tile = (row / 8u) * tiles_x + index.x / 8u;
    return unsigned(tile % slots);
}

}  // namespace lucent

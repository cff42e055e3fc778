// The samples' pinhole camera as data: one PinholeCamera in a 1-element buffer that the
// ray-generation program reads, so `lucent render` and `lucent view` run the same program
// and moving the camera re-uploads 48 bytes instead of changing variables (which recompiles
// the scene).
#pragma once

#include "lucent/device.h"

namespace sample_common {

/// W from the eye to the image centre; U and V from the centre to the right and top edges.
struct PinholeCamera {
    float3 eye, U, V, W;
};

/// The unit direction through image-plane point (sx, sy) in [-1, 1]^2, y up.
LUCENT_HD inline float3 camera_direction(const PinholeCamera& c, float sx, float sy) {
    return normalize(c.W + sx * c.U + sy * c.V);
}

/// The unit direction through the centre of pixel `i` of an image of `n` pixels (row 0 at
/// the top).
LUCENT_HD inline float3 pixel_centre_direction(const PinholeCamera& c, uint3 i, uint3 n) {
    const float sx = 2.0f * (i.x + 0.5f) / n.x - 1.0f, sy = 1.0f - 2.0f * (i.y + 0.5f) / n.y;
    return camera_direction(c, sx, sy);
}

}  // namespace sample_common

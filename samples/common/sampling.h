// Sampling routines the samples' programs share.
#pragma once

#include "lucent/device.h"

namespace sample_common {

/// A cosine-distributed unit direction around the unit normal n from (u1, u2) in [0, 1)^2
/// (Malley's method: a uniform point on the disc, projected up onto the hemisphere).
LUCENT_HD inline float3 cosine_direction(float3 n, float u1, float u2) {
    const float r = sqrtf(u1), phi = 6.2831853f * u2;
    const float3 t =
        normalize(cross(n, fabsf(n.x) > 0.5f ? make_float3(0, 1, 0) : make_float3(1, 0, 0)));
    const float3 b = cross(n, t);
    return normalize(t * (r * cosf(phi)) + b * (r * sinf(phi)) +
                     n * sqrtf(lc_max(0.0f, 1.0f - u1)));
}

}  // namespace sample_common

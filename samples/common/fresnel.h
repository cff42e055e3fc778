// Fresnel reflectance of a smooth dielectric, shared by the samples that refract (the path
// tracer's glass, IGI's specular tree).
#pragma once

#include "lucent/device/vector_math.h"

namespace sample_common {

/// Unpolarised Fresnel reflectance of a dielectric interface; cos_i >= 0 on the incident
/// side, eta = n_t / n_i. 1 under total internal reflection.
LUCENT_HD inline float fresnel_dielectric(float cos_i, float eta) {
    const float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f) return 1.0f;
    const float cos_t = sqrtf(1.0f - sin2_t);
    const float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    const float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5f * (rs * rs + rp * rp);
}

}  // namespace sample_common

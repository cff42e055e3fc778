// ray_query_rules.h: what TriangleMesh (scene/triangle_mesh.h) takes for a ray, shared by
// the query module (mesh_query_programs.h, on the GPU and through the engine on the CPU) and
// the CPU's direct queries (cpu_mesh_queries.cpp), so every path answers the same rays the
// same way.
// A ray with a NaN or infinite origin or direction component, a zero direction, or a NaN
// tmin or tmax, is a miss by definition: it is not traced, so no backend's arithmetic
// decides what it does. An infinite tmax is the engine's "no upper bound".
#pragma once

#include "lucent/device/types.h"

namespace lucent_mesh_queries {

constexpr unsigned kQueryRay = 0;  // the one ray type

/// The bits of a float: the exponent field tells finite from infinite and NaN on every
/// compiler, where x != x does not survive the GPU's fast-math compile.
LUCENT_HD inline unsigned float_bits(float f) {
    union {
        float f;
        unsigned u;
    } bits;
    bits.f = f;
    return bits.u;
}
LUCENT_HD inline bool is_finite(float f) {
    return (float_bits(f) & 0x7f800000u) != 0x7f800000u;
}
LUCENT_HD inline bool is_nan(float f) {
    return (float_bits(f) & 0x7fffffffu) > 0x7f800000u;
}
LUCENT_HD inline float positive_infinity() {
    union {
        unsigned u;
        float f;
    } bits;
    bits.u = 0x7f800000u;
    return bits.f;
}

/// The ray (o, d) over (tmin, tmax), or false when it is not a ray (see the file's comment).
LUCENT_HD inline bool query_ray(float3 o, float3 d, float tmin, float tmax, lucent::Ray& ray) {
    if (!is_finite(o.x) || !is_finite(o.y) || !is_finite(o.z) || !is_finite(d.x) ||
        !is_finite(d.y) || !is_finite(d.z) || is_nan(tmin) || is_nan(tmax))
        return false;
    if (d.x == 0.0f && d.y == 0.0f && d.z == 0.0f) return false;  // no direction
    ray = lucent::make_ray(o, d, kQueryRay, tmin,
                           tmax < lucent::kInfinity ? tmax : lucent::kInfinity);
    return true;
}

}  // namespace lucent_mesh_queries

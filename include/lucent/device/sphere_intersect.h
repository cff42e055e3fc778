// Ray/sphere intersection, written for precision (Haines, Günther and Akenine-Möller 2019,
// "Precision Improvements for Ray/Sphere Intersection", Ray Tracing Gems ch. 7): the
// discriminant from the ray's closest approach to the centre (eq. 7.5), not b² - 4ac, whose
// cancellation loses the hit of a small or distant sphere, and the two roots from the
// numerically stable form (eq. 7.6: q = -(b + sign(b) sqrt(Δ)), t0 = c / q, t1 = q / a).
// The built-in spheres' traversal on both backends and user intersection programs share it.
#pragma once

#include "lucent/device/platform.h"
#include "lucent/device/vector_math.h"

namespace lucent {

/// The two intersections of the line origin + t direction with the sphere (center,
/// radius), t0 <= t1; false when the line misses it. The direction need not be unit.
LUCENT_HD inline bool intersect_sphere(float3 origin, float3 direction, float3 center,
                                       float radius, float& t0, float& t1) {
    const float3 f = origin - center;
    const float a = dot(direction, direction);
    // The quadratic a t² - 2b t + c = 0, roots (b ± sqrt(b² - ac)) / a.
    const float b = -dot(f, direction);
    const float c = dot(f, f) - radius * radius;
    // b² - ac = a (r² - |f + (b/a) d|²), from the line's closest approach to the centre.
    const float3 closest = f + (b / a) * direction;
    const float discriminant = a * (radius * radius - dot(closest, closest));
    if (!(discriminant >= 0.0f)) return false;  // also NaN: a zero or non-finite direction
    const float q = b + (b >= 0.0f ? sqrtf(discriminant) : -sqrtf(discriminant));
    const float ta = c / q, tb = q / a;
    // q = 0 only when Δ = 0 and b = 0: the origin is the point where the line touches the
    // sphere (c = 0), a double root at t = 0 that c / q would make NaN.
    if (q == 0.0f) {
        t0 = t1 = 0.0f;
        return true;
    }
    t0 = ta < tb ? ta : tb;
    t1 = ta < tb ? tb : ta;
    return true;
}

}  // namespace lucent

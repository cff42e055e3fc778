// Watertight ray/triangle intersection (Woop, Benthin and Wald 2013, "Watertight
// Ray/Triangle Intersection", JCGT 2(1)). Shared by the CPU traversal, the tests and,
// later, the GPU megakernel, so it keeps to what g++, nvcc and NVRTC all accept.
#pragma once

#include "lucent/device/platform.h"
#include "lucent/device/vector_math.h"

namespace lucent {

/// Per-ray constants of the watertight test: the axis permutation and the shear (Sec. 3).
struct WatertightRay {
    float3 origin;
    int kx, ky, kz;    // kz: dominant axis of the direction; kx, ky keep the winding
    float sx, sy, sz;  // shear that maps the direction onto +z, scaled to unit length
};

LUCENT_HD inline float lc_axis(float3 v, int k) {
    return k == 0 ? v.x : (k == 1 ? v.y : v.z);
}

/// The axis permutation of a ray: kz the dominant axis of the direction, kx and ky the
/// other two in the order that keeps the winding (Fig. 1 of the paper).
struct WatertightAxes {
    int kx, ky, kz;
};

LUCENT_HD inline WatertightAxes watertight_axes(float3 direction) {
    float ax = direction.x < 0.0f ? -direction.x : direction.x;
    float ay = direction.y < 0.0f ? -direction.y : direction.y;
    float az = direction.z < 0.0f ? -direction.z : direction.z;
    WatertightAxes k;
    k.kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    k.kx = k.kz == 2 ? 0 : k.kz + 1;
    k.ky = k.kx == 2 ? 0 : k.kx + 1;
    // Swap kx and ky when the dominant component is negative, to preserve the winding.
    if (lc_axis(direction, k.kz) < 0.0f) {
        int tmp = k.kx;
        k.kx = k.ky;
        k.ky = tmp;
    }
    return k;
}

/// Precomputes the permutation and shear of a ray (Fig. 1 of the paper).
LUCENT_HD inline WatertightRay make_watertight_ray(float3 origin, float3 direction) {
    WatertightRay r;
    r.origin = origin;
    const WatertightAxes k = watertight_axes(direction);
    r.kx = k.kx, r.ky = k.ky, r.kz = k.kz;
    float dz = lc_axis(direction, r.kz);
    r.sx = lc_axis(direction, r.kx) / dz;
    r.sy = lc_axis(direction, r.ky) / dz;
    r.sz = 1.0f / dz;
    return r;
}

/// a*b - c*d with a correct sign, also when the exact value is 0 (Kahan's algorithm,
/// error <= 2 ulp: Jeannerod, Louvet and Muller 2013). The sign of the 2D edge functions
/// is what makes the test watertight (Sec. 4.1 of the paper, which re-evaluates exact
/// zeros in double instead); fmaf keeps it exact under any compiler's FMA contraction.
LUCENT_HD inline float difference_of_products(float a, float b, float c, float d) {
    const float cd = c * d;
    const float err = fmaf(-c, d, cd);
    const float dop = fmaf(a, b, -cd);
    return dop + err;
}

/// Watertight test of one triangle. On a hit with t in (tmin, tmax), writes t and the
/// barycentrics (u, v) of vertices 1 and 2 and returns true. Both faces are hit.
/// Every product is an explicit fmaf, so the SIMD CPU traversal computes the same bits.
LUCENT_HD inline bool intersect_triangle_watertight(const WatertightRay& r, float3 p0, float3 p1,
                                                    float3 p2, float tmin, float tmax, float& t,
                                                    float& u, float& v) {
    const float3 a = p0 - r.origin, b = p1 - r.origin, c = p2 - r.origin;
    const float az = lc_axis(a, r.kz), bz = lc_axis(b, r.kz), cz = lc_axis(c, r.kz);
    // Shear and scale the vertices into ray space (Eq. 2 and 3).
    const float ax = fmaf(-r.sx, az, lc_axis(a, r.kx)), ay = fmaf(-r.sy, az, lc_axis(a, r.ky));
    const float bx = fmaf(-r.sx, bz, lc_axis(b, r.kx)), by = fmaf(-r.sy, bz, lc_axis(b, r.ky));
    const float cx = fmaf(-r.sx, cz, lc_axis(c, r.kx)), cy = fmaf(-r.sy, cz, lc_axis(c, r.ky));
    // Scaled barycentrics as 2D edge functions (Eq. 4).
    const float e0 = difference_of_products(cx, by, cy, bx);
    const float e1 = difference_of_products(ax, cy, ay, cx);
    const float e2 = difference_of_products(bx, ay, by, ax);
    if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f))
        return false;
    const float det = e0 + e1 + e2;
    if (det == 0.0f) return false;
    // Scaled hit distance (Eq. 5), divided once the hit is known to be inside.
    const float scaled_t = fmaf(e2, r.sz * cz, fmaf(e1, r.sz * bz, e0 * (r.sz * az)));
    const float tt = scaled_t / det;
    if (!(tt > tmin && tt < tmax)) return false;
    t = tt;
    u = e1 / det;
    v = e2 / det;
    return true;
}

}  // namespace lucent

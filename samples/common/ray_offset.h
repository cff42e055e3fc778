// Where secondary rays start: a hit point moved off its surface by an offset that follows the
// floating-point spacing at the point, so shadow, bounce, photon and VPL rays neither hit the
// surface they leave nor skip nearby geometry, whatever the scene's scale or position.
// Wächter and Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing
// Gems (2019), ch. 6: the point moves along the geometric normal by a whole number of units in
// the last place of each coordinate (256 for a unit normal), which is as many ULPs at 1e6 as at
// 1e-6; near a coordinate of 0, where ULPs become denormal-small while the intersection's
// rounding does not, it moves by a fixed distance instead. The paper's fixed distance (1/65536)
// and its "near 0" (1/32) assume a scene of size about 1; here both are fractions of the
// scene's size, so a scene of 1e-6 or 1e6 is offset as one of size 1 is.
#pragma once

#include "lucent/device.h"

namespace sample_common {

/// The bits of a float as an int and back (CUDA's intrinsics on the GPU; the host compiler's
/// bit cast, which <bit>'s std::bit_cast is made of, elsewhere: NVRTC has no <bit>).
LUCENT_HD inline int float_bits(float f) {
#if LUCENT_GPU_CODE
    return __float_as_int(f);
#else
    return __builtin_bit_cast(int, f);
#endif
}
LUCENT_HD inline float bits_float(int i) {
#if LUCENT_GPU_CODE
    return __int_as_float(i);
#else
    return __builtin_bit_cast(float, i);
#endif
}

/// One coordinate of offset_ray_origin: `offset_ulps` ULPs away from 0 or towards it (as the
/// normal's sign says), or `near_offset` when |p| < `near_zero`.
LUCENT_HD inline float offset_coordinate(float p, float n, float near_zero, float near_offset) {
    const int ulps = int(256.0f * n);  // Wächter and Binder's int_scale
    const float moved = bits_float(float_bits(p) + (p < 0.0f ? -ulps : ulps));
    return fabsf(p) < near_zero ? p + near_offset * n : moved;
}

/// The origin of a ray leaving the surface at hit point `p` on the side of the unit
/// geometric normal `n` (face it towards where the ray goes: -n for a transmitted ray).
/// `scene_size` is the longest side of the scene's bounds (samples/scene_setup.h scene_size):
/// coordinates within 1/32 of it of 0 move by 1/65536 of it, the rest by 256 ULPs.
/// Trace from it with tmin 0.
LUCENT_HD inline float3 offset_ray_origin(float3 p, float3 n, float scene_size) {
    const float near_zero = scene_size * (1.0f / 32.0f);
    const float near_offset = scene_size * (1.0f / 65536.0f);
    return make_float3(offset_coordinate(p.x, n.x, near_zero, near_offset),
                       offset_coordinate(p.y, n.y, near_zero, near_offset),
                       offset_coordinate(p.z, n.z, near_zero, near_offset));
}

/// A lighter offset for scenes that stay far from the origin while being small, after the
/// same idea (Wächter and Binder, Ray Tracing Gems, ch. 6): `p` moves along the unit normal
/// `n` by the larger of their fixed distance, 1/65536 of the scene's size (which covers the
/// rounding of a hit point o + t d after a ray as long as the scene), and 2^-21 of its largest
/// coordinate, 4 to 8 float spacings there (which cover the rounding of the hit point to
/// those spacings and of the moved point). offset_ray_origin moves 256 spacings, which at 1e6
/// is 16 units: as wide as Whitted's spheres or the fog's crystal, so their shadows and
/// reflections were lost; this moves half a unit there, and the same distance as at 0 up to
/// an offset of 1e3 of a scene of size 40. For the Whitted and fog samples, whose hit points
/// are o + t d. Trace from it with tmin 0.
LUCENT_HD inline float3 offset_along_normal(float3 p, float3 n, float scene_size) {
    const float largest = fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z)));
    const float distance =
        fmaxf(scene_size * (1.0f / 65536.0f), largest * (1.0f / 2097152.0f));  // 2^-21
    return p + distance * n;
}

/// The interval of a ray between two points, as fractions of the way (the direction is `to -
/// from`): both ends are offset points, so the ray need not reach them; relative, so it is
/// the same share of the way at any scale. Not 0 and 1: the surfaces at either end then lie
/// outside the interval and their BVH boxes are culled, not entered and their triangles
/// tested (IGI's VPL shadow rays on Sponza: 6 % of the frame rate with 0 and 0.9999, H200).
/// An occluder within a thousandth of the way of either end casts no shadow.
constexpr float kSegmentStart = 0.001f, kSegmentEnd = 0.999f;

/// A shadow (visibility) ray from `from` to just short of `to`, both offset off their
/// surfaces (offset_ray_origin), or `to` a point light.
LUCENT_HD inline lucent::Ray segment_ray(float3 from, float3 to, unsigned ray_type) {
    return lucent::make_ray(from, to - from, ray_type, kSegmentStart, kSegmentEnd);
}

}  // namespace sample_common

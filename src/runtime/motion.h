// Motion blur, shared by both backends (g++ and NVRTC): where a ray's time falls among an
// object's keys, and the object at that time. The semantics are OptiX 7-9's
// (OptixMotionOptions): `keys` keys spaced evenly over [time_begin, time_end]; a time before
// or after the range is clamped to the first or last key, unless kMotionFlagStartVanish or
// kMotionFlagEndVanish says the object is absent there; between two keys everything is
// interpolated linearly (matrices per entry, SRT keys per component with the quaternion
// normalised after, vertices and centres per coordinate).
#pragma once

#include "lucent/device/types.h"
#include "lucent/device/vector_math.h"

namespace lucent::runtime {

/// What a motion range's keys are.
enum MotionKind : unsigned {
    kMotionNone = 0,      // static: no keys
    kMotionMatrix = 1,    // Transform: 12 floats per key (Matrix4x3, object to world)
    kMotionSrt = 2,       // Transform: 16 floats per key (SrtData)
    kMotionVertices = 3,  // triangles' vertices or spheres' centres: 3 floats per point per key
};

/// An object's motion as the traversal reads it: its keys lie in the scene's motion array
/// (CompiledScene::motion, LaunchParams::motion) from `offset` on.
struct MotionRange {
    unsigned kind;    // MotionKind
    unsigned keys;    // 2 or more when kind != kMotionNone
    unsigned flags;   // MotionFlags
    unsigned offset;  // first float of the keys
    float time_begin, time_end;
};

LUCENT_HD inline bool moving(const MotionRange& m) {
    return m.kind != kMotionNone;
}

/// Where `time` falls: the key before it and the fraction towards the next. False when the
/// object vanishes at that time (outside the range with the flag for that side).
LUCENT_HD inline bool motion_key(const MotionRange& m, float time, unsigned& key, float& frac) {
    if (time < m.time_begin && (m.flags & kMotionFlagStartVanish)) return false;
    if (time > m.time_end && (m.flags & kMotionFlagEndVanish)) return false;
    const float last = float(m.keys - 1);
    // Clamped into [0, keys - 1]; a NaN time lands on the first key (lc_max(NaN, 0) is 0).
    const float s =
        lc_min(lc_max((time - m.time_begin) / (m.time_end - m.time_begin) * last, 0.0f), last);
    const unsigned whole = unsigned(s);
    key = whole < m.keys - 2 ? whole : m.keys - 2;
    frac = s - float(key);
    return true;
}

/// Point `index` of a kMotionVertices range of `count` points per key, at (key, frac).
LUCENT_HD inline float3 motion_point(const float* motion, const MotionRange& m, unsigned count,
                                     unsigned index, unsigned key, float frac) {
    const float* a = motion + m.offset + 3u * (key * count + index);
    const float* b = a + 3u * count;
    return make_float3(a[0] + frac * (b[0] - a[0]), a[1] + frac * (b[1] - a[1]),
                       a[2] + frac * (b[2] - a[2]));
}

/// A moving sphere's centre `index` at `time`; false when it is absent then.
LUCENT_HD inline bool motion_center(const float* motion, const MotionRange& m, unsigned count,
                                    unsigned index, float time, float3& center) {
    unsigned key;
    float frac;
    if (!motion_key(m, time, key, frac)) return false;
    center = motion_point(motion, m, count, index, key, frac);
    return true;
}

/// Inverse of an affine 4x3 matrix; false when singular.
LUCENT_HD inline bool invert_affine(const Matrix4x3& a, Matrix4x3& inv) {
    const float* m = a.m;
    const float c00 = m[5] * m[10] - m[6] * m[9], c01 = m[6] * m[8] - m[4] * m[10],
                c02 = m[4] * m[9] - m[5] * m[8];
    const float det = m[0] * c00 + m[1] * c01 + m[2] * c02;
    if (!(fabsf(det) > 1e-20f)) return false;
    const float id = 1.0f / det;
    const float r[9] = {
        c00 * id, (m[2] * m[9] - m[1] * m[10]) * id, (m[1] * m[6] - m[2] * m[5]) * id,
        c01 * id, (m[0] * m[10] - m[2] * m[8]) * id, (m[2] * m[4] - m[0] * m[6]) * id,
        c02 * id, (m[1] * m[8] - m[0] * m[9]) * id,  (m[0] * m[5] - m[1] * m[4]) * id};
    for (int row = 0; row < 3; ++row) {
        inv.m[row * 4 + 0] = r[row * 3 + 0];
        inv.m[row * 4 + 1] = r[row * 3 + 1];
        inv.m[row * 4 + 2] = r[row * 3 + 2];
        inv.m[row * 4 + 3] = -(r[row * 3] * m[3] + r[row * 3 + 1] * m[7] + r[row * 3 + 2] * m[11]);
    }
    return true;
}

/// The object-to-world matrix of one SRT key (OptiX's OptixSRTData): T * R * S.
LUCENT_HD inline Matrix4x3 srt_to_matrix(const SrtData& k) {
    // R of the unit quaternion (x, y, z, w).
    const float x = k.qx, y = k.qy, z = k.qz, w = k.qw;
    const float r[9] = {1.0f - 2.0f * (y * y + z * z), 2.0f * (x * y - z * w),
                        2.0f * (x * z + y * w),        2.0f * (x * y + z * w),
                        1.0f - 2.0f * (x * x + z * z), 2.0f * (y * z - x * w),
                        2.0f * (x * z - y * w),        2.0f * (y * z + x * w),
                        1.0f - 2.0f * (x * x + y * y)};
    // S, upper triangular, with the pivot as its translation.
    const float s[12] = {k.sx, k.a, k.b, k.pvx, 0.0f, k.sy, k.c, k.pvy, 0.0f, 0.0f, k.sz, k.pvz};
    const float t[3] = {k.tx, k.ty, k.tz};
    Matrix4x3 out;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j) {
            const float v = r[i * 3] * s[j] + r[i * 3 + 1] * s[4 + j] + r[i * 3 + 2] * s[8 + j];
            out.m[i * 4 + j] = j == 3 ? v + t[i] : v;
        }
    return out;
}

/// The SRT key at (key, frac): components interpolated linearly, the quaternion normalised
/// after (nlerp).
LUCENT_HD inline SrtData srt_at(const float* keys, unsigned key, float frac) {
    const float* a = keys + 16u * key;
    const float* b = a + 16;
    float v[16];
    for (int i = 0; i < 16; ++i) v[i] = a[i] + frac * (b[i] - a[i]);
    SrtData k;
    k.sx = v[0], k.a = v[1], k.b = v[2], k.pvx = v[3], k.sy = v[4], k.c = v[5], k.pvy = v[6];
    k.sz = v[7], k.pvz = v[8], k.tx = v[13], k.ty = v[14], k.tz = v[15];
    const float norm = sqrtf(v[9] * v[9] + v[10] * v[10] + v[11] * v[11] + v[12] * v[12]);
    const float inv = norm > 0.0f ? 1.0f / norm : 0.0f;
    k.qx = v[9] * inv, k.qy = v[10] * inv, k.qz = v[11] * inv, k.qw = v[12] * inv;
    return k;
}

/// A motion Transform's matrices at `time`; false when it vanishes then (or is singular
/// there: nothing below it can be hit).
LUCENT_HD inline bool motion_transform_at(const float* motion, const MotionRange& m, float time,
                                          Matrix4x3& to_world, Matrix4x3& to_object) {
    unsigned key;
    float frac;
    if (!motion_key(m, time, key, frac)) return false;
    const float* keys = motion + m.offset;
    if (m.kind == kMotionSrt) {
        to_world = srt_to_matrix(srt_at(keys, key, frac));
    } else {
        const float* a = keys + 12u * key;
        for (int i = 0; i < 12; ++i) to_world.m[i] = a[i] + frac * (a[12 + i] - a[i]);
    }
    return invert_affine(to_world, to_object);
}

}  // namespace lucent::runtime

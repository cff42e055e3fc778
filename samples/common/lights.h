// The light sources of scene::Scene as the samples' programs read them from buffers, and the
// sampling of area lights they share: a uniform point by area, and the choice of one light
// in proportion to its power (a cumulative distribution the host makes, light_cdf in
// samples/scene_setup.h).
#pragma once

#include "lucent/device.h"

namespace sample_common {

struct PointLight {
    float3 position;
    float3 intensity;
};

/// An emitting parallelogram corner + s edge1 + t edge2 (s, t in [0, 1]), or with `triangle`
/// the triangle s, t >= 0, s + t <= 1 (an emissive mesh triangle); it emits on the side
/// cross(edge1, edge2) points to (scene::AreaLight).
struct AreaLight {
    float3 corner, edge1, edge2;
    float3 emission;
    unsigned triangle;  // 0: parallelogram, 1: triangle
};

LUCENT_HD inline float light_area(const AreaLight& l) {
    return length(cross(l.edge1, l.edge2)) * (l.triangle ? 0.5f : 1.0f);
}

/// The unit normal of the emitting side.
LUCENT_HD inline float3 light_normal(const AreaLight& l) {
    return normalize(cross(l.edge1, l.edge2));
}

/// A uniformly distributed point of the light from (u, v) in [0, 1)^2. A triangle maps the
/// square continuously (Shirley and Chiu's sqrt warp: s = sqrt(u) (1 - v), t = sqrt(u) v), so
/// stratified (u, v) stay stratified on it.
LUCENT_HD inline float3 light_point(const AreaLight& l, float u, float v) {
    if (!l.triangle) return l.corner + u * l.edge1 + v * l.edge2;
    const float r = sqrtf(u);
    return l.corner + (r * (1.0f - v)) * l.edge1 + (r * v) * l.edge2;
}

/// The distance t at which the ray origin + t direction (unit) meets the light's emitting
/// side, or 0 when it does not.
LUCENT_HD inline float light_hit_distance(const AreaLight& l, float3 origin, float3 direction) {
    const float3 normal = cross(l.edge1, l.edge2);
    const float denom = dot(direction, normal);
    if (denom >= 0.0f) return 0.0f;  // its back, which does not emit
    const float t = dot(l.corner - origin, normal) / denom;
    const float3 w = origin + t * direction - l.corner;
    const float area2 = dot(normal, normal);
    const float s = dot(cross(w, l.edge2), normal) / area2;
    const float v = dot(cross(l.edge1, w), normal) / area2;
    const bool inside = l.triangle ? s >= 0.0f && v >= 0.0f && s + v <= 1.0f
                                   : s >= 0.0f && s <= 1.0f && v >= 0.0f && v <= 1.0f;
    return inside && t > 0.0f ? t : 0.0f;
}

/// The light that uniform u in [0, 1) picks from the cumulative distribution `cdf` (one
/// entry per light, increasing, the last 1): the first whose entry exceeds u.
LUCENT_HD inline unsigned pick_light(lucent::BufferView<const float> cdf, float u) {
    unsigned lo = 0, hi = cdf.count() - 1;
    while (lo < hi) {
        const unsigned mid = (lo + hi) / 2;
        if (cdf[mid] > u) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

/// The probability with which pick_light picks light l.
LUCENT_HD inline float light_probability(lucent::BufferView<const float> cdf, unsigned l) {
    return cdf[l] - (l > 0 ? cdf[l - 1u] : 0.0f);
}

}  // namespace sample_common

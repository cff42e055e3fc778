// Programs of the motion blur tests: a ray generation that traces (or asks occluded() for)
// each listed ray at its own time, and hit and miss programs that record what they see,
// ray_time() included.
#pragma once

#include "lucent/device/sphere_intersect.h"
#include "tests/programs/common.h"

namespace lucent_tests {
inline namespace motion_module {
LUCENT_MODULE(test_motion, lucent::kUsesOccluded)

struct MotionRay {
    float3 origin, direction;
    float time;
    unsigned occlusion;  // 1: occluded() instead of trace()
};

struct MotionPayload {
    int hit;        // -1: neither program ran, 0: miss, 1: closest hit
    unsigned id;    // the closest hit's `id` variable
    float t;        // t_hit() in the closest hit
    float time;     // ray_time() in the closest hit or the miss program
    unsigned prim;  // primitive_index()
    float3 normal;  // the attributes' object-space normal
    unsigned occluded;
    float generation_time;  // ray_time() in the ray-generation program (outside a trace)
};

struct MotionCastRecord {
    Handle top;
    BufferView<MotionRay> rays;
    BufferView<MotionPayload> results;
};
LUCENT_RECORD(MotionCastRecord, top, rays, results)

LUCENT_RAY_GENERATION(motion_cast, MotionCastRecord) {
    const unsigned i = launch_index().x;
    const MotionRay r = rec.rays[i];
    MotionPayload p{};
    p.hit = -1;
    const Ray ray = make_ray(r.origin, r.direction, 0, 0.0f, kInfinity, r.time);
    if (r.occlusion)
        p.occluded = occluded(rec.top, ray) ? 1u : 0u;
    else
        trace(rec.top, ray, p);
    p.generation_time = ray_time();
    rec.results[i] = p;
}

LUCENT_MISS(motion_miss, NoRecord, MotionPayload) {
    prd.hit = 0;
    prd.time = ray_time();
}

LUCENT_CLOSEST_HIT(motion_sphere_hit, IdRecord, MotionPayload, BuiltinSphereAttributes) {
    prd.hit = 1;
    prd.id = rec.id;
    prd.t = t_hit();
    prd.time = ray_time();
    prd.prim = primitive_index();
    prd.normal = attr.normal;
}

LUCENT_CLOSEST_HIT(motion_triangle_hit, IdRecord, MotionPayload, TriangleAttributes) {
    prd.hit = 1;
    prd.id = rec.id;
    prd.t = t_hit();
    prd.time = ray_time();
    prd.prim = primitive_index();
    prd.normal = attr.geometric_normal;
}

/// A custom sphere that moves by itself: its intersection program reads ray_time() (how a
/// custom primitive moves, as in OptiX), centre = `center` + time * `velocity`.
struct TimedSphereRecord {
    float3 center, velocity;
    float radius;
};
LUCENT_RECORD(TimedSphereRecord, center, velocity, radius)

LUCENT_INTERSECTION(timed_sphere_intersect, TimedSphereRecord, BuiltinSphereAttributes) {
    const Ray& ray = current_ray();
    const float3 c = rec.center + ray_time() * rec.velocity;
    float t0, t1;
    if (!lucent::intersect_sphere(ray.origin, ray.direction, c, rec.radius, t0, t1)) return;
    const float ts[2] = {t0, t1};
    for (int side = 0; side < 2; ++side)
        if (potential_intersection(ts[side])) {
            attr.normal = normalize(ray.origin + ts[side] * ray.direction - c);
            attr.entering = side == 0 ? 1u : 0u;
            if (report_intersection(0)) return;
        }
}

/// Its box over times [0, 1].
LUCENT_BOUNDING_BOX(timed_sphere_bounds, TimedSphereRecord) {
    const float3 r = make_float3(rec.radius);
    const float3 end = rec.center + rec.velocity;
    box.lo = fminf(rec.center, end) - r;
    box.hi = fmaxf(rec.center, end) + r;
}

}  // namespace motion_module
}  // namespace lucent_tests

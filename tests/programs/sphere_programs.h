// Programs of the built-in sphere tests (GeometrySpheres): a ray generation that traces, or
// asks occluded() for, each listed ray with its own interval and flags, and hit programs
// that record BuiltinSphereAttributes and what else the hit shows.
#pragma once

#include "tests/programs/common.h"

namespace lucent_tests {
inline namespace sphere_module {
LUCENT_MODULE(test_spheres, lucent::kUsesOccluded, lucent::kUsesRayFlags)

struct SphereRay {
    float3 origin, direction;
    float tmin, tmax;
    unsigned flags;      // RayFlags
    unsigned occlusion;  // 1: occluded() instead of trace()
};

struct SpherePayload {
    int hit;  // -1: neither miss nor closest hit ran, 0: miss, 1: closest hit
    unsigned id;            // the closest hit's `id` variable
    float t;                // t_hit() in the closest hit
    unsigned prim;          // primitive_index()
    float3 object_normal;   // BuiltinSphereAttributes::normal
    float3 world_normal;    // object_to_world_normal of it
    unsigned entering;      // BuiltinSphereAttributes::entering
    unsigned anyhit_count;  // any-hit invocations
    float anyhit_t[2];      // t_hit() of the first two any-hits
    unsigned occluded;      // occluded()'s answer
};

struct SphereCastRecord {
    Handle top;
    BufferView<SphereRay> rays;
    BufferView<SpherePayload> results;
};
LUCENT_RECORD(SphereCastRecord, top, rays, results)

LUCENT_RAY_GENERATION(sphere_cast, SphereCastRecord) {
    const unsigned i = launch_index().x;
    const SphereRay r = rec.rays[i];
    SpherePayload p{};
    p.hit = -1;
    const Ray ray = make_ray(r.origin, r.direction, 0, r.tmin, r.tmax);
    if (r.occlusion)
        p.occluded = occluded(rec.top, ray, Occlusion::kExact, r.flags) ? 1u : 0u;
    else
        trace(rec.top, ray, p, r.flags);
    rec.results[i] = p;
}

LUCENT_MISS(sphere_miss, NoRecord, SpherePayload) {
    prd.hit = 0;
}

LUCENT_CLOSEST_HIT(sphere_hit, IdRecord, SpherePayload, BuiltinSphereAttributes) {
    prd.hit = 1;
    prd.id = rec.id;
    prd.t = t_hit();
    prd.prim = primitive_index();
    prd.object_normal = attr.normal;
    prd.world_normal = normalize(object_to_world_normal(attr.normal));
    prd.entering = attr.entering;
}

/// Counts candidates and keeps their t; ignores them all when `ignore` is set.
struct SphereAnyHitRecord {
    unsigned ignore;
};
LUCENT_RECORD(SphereAnyHitRecord, ignore)

LUCENT_ANY_HIT(sphere_any_hit, SphereAnyHitRecord, SpherePayload, BuiltinSphereAttributes) {
    if (prd.anyhit_count < 2) prd.anyhit_t[prd.anyhit_count] = t_hit();
    ++prd.anyhit_count;
    if (rec.ignore) ignore_intersection();
}

/// A triangle beside spheres in one group: the same payload, its own attributes.
LUCENT_CLOSEST_HIT(sphere_test_triangle_hit, IdRecord, SpherePayload, TriangleAttributes) {
    prd.hit = 1;
    prd.id = rec.id;
    prd.t = t_hit();
    prd.prim = primitive_index();
}

}  // namespace sphere_module
}  // namespace lucent_tests

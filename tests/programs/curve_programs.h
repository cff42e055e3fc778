// Programs of the built-in curve tests (GeometryCurves): a ray generation that traces, or
// asks occluded() for, each listed ray with its own interval, and hit programs that record
// BuiltinCurveAttributes and what else the hit shows.
#pragma once

#include "tests/programs/common.h"

namespace lucent_tests {
inline namespace curve_module {
LUCENT_MODULE(test_curves, lucent::kUsesOccluded)

struct CurveRay {
    float3 origin, direction;
    float tmin, tmax;
    unsigned occlusion;  // 1: occluded() instead of trace()
};

struct CurvePayload {
    int hit;                // -1: neither miss nor closest hit ran, 0: miss, 1: closest hit
    unsigned id;            // the closest hit's `id` variable
    float t;                // t_hit() in the closest hit
    unsigned prim;          // primitive_index()
    float3 object_normal;   // BuiltinCurveAttributes::normal
    float3 world_normal;    // object_to_world_normal of it
    float u;                // BuiltinCurveAttributes::u
    unsigned entering;      // BuiltinCurveAttributes::entering
    unsigned anyhit_count;  // any-hit invocations
    float anyhit_t[2];      // t_hit() of the first two any-hits
    unsigned occluded;      // occluded()'s answer
};

struct CurveCastRecord {
    Handle top;
    BufferView<CurveRay> rays;
    BufferView<CurvePayload> results;
};
LUCENT_RECORD(CurveCastRecord, top, rays, results)

LUCENT_RAY_GENERATION(curve_cast, CurveCastRecord) {
    const unsigned i = launch_index().x;
    const CurveRay r = rec.rays[i];
    CurvePayload p{};
    p.hit = -1;
    const Ray ray = make_ray(r.origin, r.direction, 0, r.tmin, r.tmax);
    if (r.occlusion)
        p.occluded = occluded(rec.top, ray) ? 1u : 0u;
    else
        trace(rec.top, ray, p);
    rec.results[i] = p;
}

LUCENT_MISS(curve_miss, NoRecord, CurvePayload) {
    prd.hit = 0;
}

LUCENT_CLOSEST_HIT(curve_hit, IdRecord, CurvePayload, BuiltinCurveAttributes) {
    prd.hit = 1;
    prd.id = rec.id;
    prd.t = t_hit();
    prd.prim = primitive_index();
    prd.object_normal = attr.normal;
    prd.world_normal = normalize(object_to_world_normal(attr.normal));
    prd.u = attr.u;
    prd.entering = attr.entering;
}

/// Counts candidates and keeps their t; ignores them all when `ignore` is set.
struct CurveAnyHitRecord {
    unsigned ignore;
};
LUCENT_RECORD(CurveAnyHitRecord, ignore)

LUCENT_ANY_HIT(curve_any_hit, CurveAnyHitRecord, CurvePayload, BuiltinCurveAttributes) {
    if (prd.anyhit_count < 2) prd.anyhit_t[prd.anyhit_count] = t_hit();
    ++prd.anyhit_count;
    if (rec.ignore) ignore_intersection();
}

/// A sphere's closest hit, to show that a curve's attributes are not a sphere's.
LUCENT_CLOSEST_HIT(curve_test_sphere_hit, IdRecord, CurvePayload, BuiltinSphereAttributes) {
    prd.hit = 1;
    prd.id = rec.id;
}

}  // namespace curve_module
}  // namespace lucent_tests

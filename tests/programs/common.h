// Programs shared by the behavioural tests: a ray caster that traces rays listed in a
// buffer and stores each payload, a miss program, spheres (custom intersection) and
// closest-hit programs for spheres and built-in triangles.
#pragma once

#include "lucent/device.h"

namespace lucent_tests {
using namespace lucent;
// Each test module in its own inline namespace: its own LUCENT_MODULE, while the tests
// still name its programs and types unqualified.
inline namespace common_module {
LUCENT_MODULE(test_common)

/// What every test ray carries back: who handled it and what it saw.
struct TestPayload {
    int hit;                // -1: neither miss nor closest hit ran, 0: miss, 1: closest hit
    unsigned id;            // the `id` variable of the closest hit's record
    float t;                // t_hit() in the closest hit
    unsigned prim;          // primitive_index() in the closest hit
    float3 point;           // world-space hit point (current_ray() in the closest hit)
    float3 normal;          // world-space unit normal
    float3 object_point;    // world_to_object_point(point)
    float2 uv;              // barycentrics or interpolated texture coordinates
    unsigned anyhit_count;  // any-hit invocations
    float anyhit_t;         // t_hit() in the last any-hit
    int depth;              // trace nesting depth of this payload
    float path_length;      // sum of t over recursive bounces
    float3 ray_origin;      // current_ray() in the closest hit
    float3 ray_direction;
    float ray_tmax;
};

LUCENT_HD inline TestPayload make_test_payload() {
    TestPayload p{};
    p.hit = -1;
    p.id = 0xffffffffu;
    p.t = -1.0f;
    p.prim = 0xffffffffu;
    p.depth = 1;
    return p;
}

/// One ray for the caster (a user struct stored in a buffer).
struct CastRay {
    float3 origin;
    float3 direction;
};

// ---- ray generation: trace rays[i] against `top`, store the payload ------------
struct CasterRecord {
    Handle top;
    BufferView<CastRay> rays;
    BufferView<TestPayload> results;
};
LUCENT_RECORD(CasterRecord, top, rays, results)

LUCENT_RAY_GENERATION(common_cast, CasterRecord) {
    const unsigned i = launch_index().x;
    const CastRay r = rec.rays[i];
    TestPayload p = make_test_payload();
    trace(rec.top, make_ray(r.origin, r.direction, 0, 1e-4f), p);
    rec.results[i] = p;
}

LUCENT_MISS(common_miss, NoRecord, TestPayload) {
    prd.hit = 0;
}

// ---- spheres: float4 (centre, radius) per primitive ----------------------------
struct SphereAttributes {
    float3 normal;  // object space, unit
};

struct SphereRecord {
    BufferView<float4> spheres;
};
LUCENT_RECORD(SphereRecord, spheres)

/// Reports the nearer root if inside the interval, else the farther one (OptiX sample idiom).
/// Any attribute struct with a `normal` member works; other members are left as they are.
template <class Attributes>
LUCENT_HD inline void intersect_sphere(float4 s, unsigned material_index, Attributes& attr) {
    const Ray& ray = current_ray();
    const float3 centre = make_float3(s.x, s.y, s.z);
    const float3 o = ray.origin - centre;
    const float a = dot(ray.direction, ray.direction);
    const float b = dot(o, ray.direction);
    const float c = dot(o, o) - s.w * s.w;
    const float disc = b * b - a * c;
    if (disc < 0.0f) return;
    const float root = sqrtf(disc);
    const float t0 = (-b - root) / a, t1 = (-b + root) / a;
    if (potential_intersection(t0)) {
        attr.normal = (o + t0 * ray.direction) / s.w;
        if (report_intersection(material_index)) return;
    }
    if (potential_intersection(t1)) {
        attr.normal = (o + t1 * ray.direction) / s.w;
        report_intersection(material_index);
    }
}

LUCENT_INTERSECTION(common_sphere_intersect, SphereRecord, SphereAttributes) {
    intersect_sphere(rec.spheres[prim], 0, attr);
}

LUCENT_BOUNDING_BOX(common_sphere_bounds, SphereRecord) {
    const float4 s = rec.spheres[prim];
    box.lo = make_float3(s.x - s.w, s.y - s.w, s.z - s.w);
    box.hi = make_float3(s.x + s.w, s.y + s.w, s.z + s.w);
}

// ---- closest hits: record what was hit ------------------------------------------
struct IdRecord {
    unsigned id;
};
LUCENT_RECORD(IdRecord, id)

/// Fills the payload fields every closest hit shares.
LUCENT_HD inline void record_hit(const IdRecord& rec, TestPayload& prd, float3 object_normal) {
    const Ray& ray = current_ray();
    prd.hit = 1;
    prd.id = rec.id;
    prd.t = t_hit();
    prd.prim = primitive_index();
    prd.point = ray.origin + t_hit() * ray.direction;
    prd.normal = normalize(object_to_world_normal(object_normal));
    prd.object_point = world_to_object_point(prd.point);
    prd.ray_origin = ray.origin;
    prd.ray_direction = ray.direction;
    prd.ray_tmax = ray.tmax;
}

LUCENT_CLOSEST_HIT(common_sphere_hit, IdRecord, TestPayload, SphereAttributes) {
    record_hit(rec, prd, attr.normal);
}

LUCENT_CLOSEST_HIT(common_triangle_hit, IdRecord, TestPayload, TriangleAttributes) {
    record_hit(rec, prd, attr.geometric_normal);
    prd.uv = attr.barycentrics;
}

}  // namespace common_module
}  // namespace lucent_tests

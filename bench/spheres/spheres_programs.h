// spheres_programs.h: the program module of `lucent bench spheres`. Primary rays from a
// pinhole camera into a field of spheres, traced two ways the bench times against each
// other in one run: the engine's built-in spheres (GeometrySpheres), and the same spheres as
// a user's custom primitive (a bounding-box and an intersection program over the same
// buffers, with the same intersection formula, lucent/device/sphere_intersect.h). What
// differs is only what the engine does for a built-in primitive: no program dispatch, no
// record reads, no potential/report round trip per candidate.
#pragma once

#include "lucent/device.h"
#include "lucent/device/sphere_intersect.h"

namespace lucent_bench_spheres {
LUCENT_MODULE(lucent_bench_spheres)
using namespace lucent;

constexpr unsigned kBenchRay = 0;

/// 8 bytes: the hit's t and sphere (the miss writes -1 and ~0u).
struct SphereHit {
    float t;
    unsigned prim;
};

struct CameraRecord {
    Handle scene;
    float3 eye, u, v, w;  // the image plane: w + x u + y v for x, y in [-1, 1]
    BufferView<float> t;
    BufferView<unsigned> prim;
};
LUCENT_RECORD(CameraRecord, scene, eye, u, v, w, t, prim)

LUCENT_RAY_GENERATION(sphere_primary_rays, CameraRecord) {
    const uint3 i = launch_index(), n = launch_size();
    const float x = (i.x + 0.5f) / n.x * 2.0f - 1.0f, y = 1.0f - (i.y + 0.5f) / n.y * 2.0f;
    SphereHit hit;
    trace(rec.scene, make_ray(rec.eye, rec.w + x * rec.u + y * rec.v, kBenchRay, 0.0f), hit);
    const unsigned k = i.y * n.x + i.x;
    rec.t[k] = hit.t;
    rec.prim[k] = hit.prim;
}

LUCENT_MISS(sphere_miss, NoRecord, SphereHit) {
    prd.t = -1.0f;
    prd.prim = ~0u;
}

LUCENT_CLOSEST_HIT(builtin_sphere_hit, NoRecord, SphereHit, BuiltinSphereAttributes) {
    prd.t = t_hit();
    prd.prim = primitive_index();
}

// ---- the same spheres as a custom primitive -------------------------------------------
/// What the built-in spheres give their hit programs, so both paths compute the same.
struct CustomSphereAttributes {
    float3 normal;
    unsigned entering;
};

struct CustomSpheresRecord {
    BufferView<float3> centers;
    BufferView<float> radii;
};
LUCENT_RECORD(CustomSpheresRecord, centers, radii)

LUCENT_INTERSECTION(custom_sphere_intersect, CustomSpheresRecord, CustomSphereAttributes) {
    const Ray& ray = current_ray();
    const float3 c = rec.centers[prim];
    const float r = rec.radii[prim];
    float t0, t1;
    if (!intersect_sphere(ray.origin, ray.direction, c, r, t0, t1)) return;
    if (potential_intersection(t0)) {
        attr.normal = normalize((ray.origin - c + t0 * ray.direction) * (1.0f / r));
        attr.entering = 1u;
        if (report_intersection(0)) return;
    }
    if (potential_intersection(t1)) {
        attr.normal = normalize((ray.origin - c + t1 * ray.direction) * (1.0f / r));
        attr.entering = 0u;
        report_intersection(0);
    }
}

LUCENT_BOUNDING_BOX(custom_sphere_bounds, CustomSpheresRecord) {
    const float3 c = rec.centers[prim];
    const float r = rec.radii[prim];
    box.lo = c - make_float3(r, r, r);
    box.hi = c + make_float3(r, r, r);
}

LUCENT_CLOSEST_HIT(custom_sphere_hit, NoRecord, SphereHit, CustomSphereAttributes) {
    prd.t = t_hit();
    prd.prim = primitive_index();
}

}  // namespace lucent_bench_spheres

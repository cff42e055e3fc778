// curves_programs.h: the program module of `lucent bench curves`. A procedural head of hair
// (built-in cubic B-spline curves over a built-in sphere): primary rays from a pinhole
// camera, then one cosine-distributed diffuse ray from each primary hit, each set in its own
// launch so that each is timed alone.
#pragma once

#include "lucent/device.h"

namespace lucent_bench_curves {
LUCENT_MODULE(lucent_bench_curves)
using namespace lucent;

constexpr unsigned kBenchRay = 0;

/// The hit's t (-1 for a miss) and world-space unit normal.
struct HairHit {
    float t;
    float3 normal;
};

struct HairCameraRecord {
    Handle scene;
    float3 eye, u, v, w;  // the image plane: w + x u + y v for x, y in [-1, 1]
    float offset;         // how far diffuse rays start off the surface
    unsigned seed;
    BufferView<float4> points;   // primary hits: position, w = 1 for a hit, 0 for a miss
    BufferView<float4> normals;  // their normals, facing the camera
    BufferView<unsigned> diffuse_hits;  // 1 where the diffuse ray hit something
};
LUCENT_RECORD(HairCameraRecord, scene, eye, u, v, w, offset, seed, points, normals,
              diffuse_hits)

LUCENT_RAY_GENERATION(hair_primary_rays, HairCameraRecord) {
    const uint3 i = launch_index(), n = launch_size();
    const float x = (i.x + 0.5f) / n.x * 2.0f - 1.0f, y = 1.0f - (i.y + 0.5f) / n.y * 2.0f;
    const float3 direction = rec.w + x * rec.u + y * rec.v;
    HairHit hit;
    trace(rec.scene, make_ray(rec.eye, direction, kBenchRay, 0.0f), hit);
    const unsigned k = i.y * n.x + i.x;
    const bool found = hit.t >= 0.0f;
    rec.points[k] = make_float4(rec.eye + hit.t * direction, found ? 1.0f : 0.0f);
    rec.normals[k] = make_float4(faceforward(hit.normal, direction), 0.0f);
}

/// A 32-bit hash (the PCG output permutation of a counter), for the diffuse directions.
LUCENT_HD inline unsigned hash32(unsigned x) {
    const unsigned state = x * 747796405u + 2891336453u;
    const unsigned word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

LUCENT_RAY_GENERATION(hair_diffuse_rays, HairCameraRecord) {
    const uint3 i = launch_index(), n = launch_size();
    const unsigned k = i.y * n.x + i.x;
    const float4 point = rec.points[k];
    if (point.w == 0.0f) {
        rec.diffuse_hits[k] = 0u;
        return;
    }
    const float3 normal = make_float3(rec.normals[k]);
    // Cosine-distributed about the normal (Malley's method) in a frame around it.
    const unsigned h1 = hash32(k ^ rec.seed), h2 = hash32(h1);
    const float r1 = (h1 >> 8) * (1.0f / 16777216.0f), r2 = (h2 >> 8) * (1.0f / 16777216.0f);
    const float radius = sqrtf(r1), phi = 6.2831853f * r2;
    const float3 helper = fabsf(normal.x) > 0.5f ? make_float3(0, 1, 0) : make_float3(1, 0, 0);
    const float3 a = normalize(cross(helper, normal)), b = cross(normal, a);
    const float3 direction = radius * cosf(phi) * a + radius * sinf(phi) * b +
                             sqrtf(lc_max(0.0f, 1.0f - r1)) * normal;
    HairHit hit;
    trace(rec.scene,
          make_ray(make_float3(point) + rec.offset * normal, direction, kBenchRay, 0.0f), hit);
    rec.diffuse_hits[k] = hit.t >= 0.0f ? 1u : 0u;
}

LUCENT_MISS(hair_miss, NoRecord, HairHit) {
    prd.t = -1.0f;
    prd.normal = make_float3(0.0f);
}

LUCENT_CLOSEST_HIT(hair_strand_hit, NoRecord, HairHit, BuiltinCurveAttributes) {
    prd.t = t_hit();
    prd.normal = normalize(object_to_world_normal(attr.normal));
}

LUCENT_CLOSEST_HIT(hair_head_hit, NoRecord, HairHit, BuiltinSphereAttributes) {
    prd.t = t_hit();
    prd.normal = normalize(object_to_world_normal(attr.normal));
}

}  // namespace lucent_bench_curves

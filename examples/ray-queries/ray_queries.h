// ray_queries.h: the program module of the ray-queries example. Ray tracing without an
// image (Parker et al., CACM 2013: "collision detection, line-of-sight queries"): each
// launch index answers one query of a batch read from input buffers and writes its answer
// to an output buffer.
//   entry 0, line_of_sight: is the segment between from[i] and to[i] free of the mesh?
//   entry 1, closest_distance: how far along ray i (origin[i], direction[i]) is the first surface,
//            and which triangle is it?
#pragma once

#include "lucent/device.h"

namespace ray_queries {
// line_of_sight calls occluded(), so the module declares it.
LUCENT_MODULE(ray_queries, lucent::kUsesOccluded)

using lucent::BufferView;
using lucent::Handle;

constexpr unsigned kQueryRay = 0;  // the one ray type
constexpr unsigned kNoTriangle = 0xffffffffu;

/// What a distance query's ray carries back.
struct HitPayload {
    float t;            // distance along the (unit) direction; -1: nothing hit
    unsigned triangle;  // the triangle hit, or kNoTriangle
};

struct LineOfSightRecord {
    BufferView<const float3> from, to;
    BufferView<unsigned> visible;  // 1: nothing between from and to; 0: blocked
    Handle mesh;
};
LUCENT_RECORD(LineOfSightRecord, from, to, visible, mesh)

// occluded() answers "is anything in between": no hit program runs, and traversal stops at
// the first triangle found. The ray spans exactly the segment: t in (0, 1) of to - from.
LUCENT_RAY_GENERATION(line_of_sight, LineOfSightRecord) {
    const unsigned i = lucent::launch_index().x;
    const float3 a = rec.from[i], b = rec.to[i];
    const bool blocked =
        lucent::occluded(rec.mesh, lucent::make_ray(a, b - a, kQueryRay, 0.0f, 1.0f));
    rec.visible[i] = blocked ? 0u : 1u;
}

struct DistanceRecord {
    BufferView<const float3> origin, direction;  // directions of unit length
    BufferView<float> distance;                  // -1 where the ray hits nothing
    BufferView<unsigned> triangle;               // kNoTriangle where it hits nothing
    float max_distance;                          // farther hits do not count
    Handle mesh;
};
LUCENT_RECORD(DistanceRecord, origin, direction, distance, triangle, max_distance, mesh)

// trace() finds the closest hit; its closest-hit (or miss) program fills the payload.
LUCENT_RAY_GENERATION(closest_distance, DistanceRecord) {
    const unsigned i = lucent::launch_index().x;
    HitPayload hit{-1.0f, kNoTriangle};
    lucent::trace(
        rec.mesh,
        lucent::make_ray(rec.origin[i], rec.direction[i], kQueryRay, 0.0f, rec.max_distance), hit);
    rec.distance[i] = hit.t;
    rec.triangle[i] = hit.triangle;
}

LUCENT_CLOSEST_HIT(record_hit, lucent::NoRecord, HitPayload, lucent::TriangleAttributes) {
    prd.t = lucent::t_hit();
    prd.triangle = lucent::primitive_index();
}

LUCENT_MISS(record_miss, lucent::NoRecord, HitPayload) {
    prd.t = -1.0f;
    prd.triangle = kNoTriangle;
}

}  // namespace ray_queries

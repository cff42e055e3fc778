// mesh_query_programs.h: the program module behind TriangleMesh (scene/triangle_mesh.h) on
// the GPU, where it is compiled by NVRTC into the megakernel (on the CPU the queries call
// the traversal directly, cpu_mesh_queries.h; this module runs there when a mesh is asked
// for a JIT check or a device list). Each launch index answers one ray of a batch the host
// copied from the caller's arrays into input buffers, and writes its answer to output
// buffers.
//   closest_hits: the first surface along each ray (t, triangle, barycentrics, unit normal)
//   any_hits:     is anything on the ray in (tmin, tmax)? (occluded(): no hit program runs)
// Which rays are rays: ray_query_rules.h.
#pragma once

#include "lucent/device.h"
#include "ray_query_rules.h"  // beside this file

namespace lucent_mesh_queries {
// any_hits calls occluded(), so the module declares it.
LUCENT_MODULE(lucent_mesh_queries, lucent::kUsesOccluded)

using lucent::BufferView;
using lucent::Handle;

/// What a closest-hit query's ray carries back (prim -1: nothing hit).
struct QueryHit {
    float t;
    int prim;
    float2 uv;
    float3 normal;
};

/// The inputs both queries read: one ray per launch index, and its interval. tmin and tmax
/// hold one value for every ray (count 1) or one per ray.
struct RayBatch {
    BufferView<const float3> origins, directions;
    BufferView<const float> tmin, tmax;
};

/// Ray i of the batch, or false when it is not a ray (query_ray, ray_query_rules.h).
LUCENT_HD inline bool batch_ray(const RayBatch& batch, unsigned i, lucent::Ray& ray) {
    return query_ray(batch.origins[i], batch.directions[i],
                     batch.tmin[batch.tmin.count() == 1 ? 0u : i],
                     batch.tmax[batch.tmax.count() == 1 ? 0u : i], ray);
}

struct ClosestHitsRecord {
    BufferView<const float3> origins, directions;
    BufferView<const float> tmin, tmax;
    BufferView<float> t;  // +inf on a miss
    BufferView<int> prim;
    BufferView<float2> uv;
    BufferView<float3> normal;
    Handle mesh;
};
LUCENT_RECORD(ClosestHitsRecord, origins, directions, tmin, tmax, t, prim, uv, normal, mesh)

LUCENT_RAY_GENERATION(closest_hits, ClosestHitsRecord) {
    const unsigned i = lucent::launch_index().x;
    QueryHit hit{positive_infinity(), -1, make_float2(0.0f, 0.0f), make_float3(0.0f)};
    lucent::Ray ray;
    if (batch_ray(RayBatch{rec.origins, rec.directions, rec.tmin, rec.tmax}, i, ray))
        lucent::trace(rec.mesh, ray, hit);
    rec.t[i] = hit.t;
    rec.prim[i] = hit.prim;
    rec.uv[i] = hit.uv;
    rec.normal[i] = hit.normal;
}

LUCENT_CLOSEST_HIT(record_hit, lucent::NoRecord, QueryHit, lucent::TriangleAttributes) {
    prd.t = lucent::t_hit();
    prd.prim = int(lucent::primitive_index());
    prd.uv = attr.barycentrics;
    prd.normal = attr.geometric_normal;  // unit length, in the mesh's winding order
}

LUCENT_MISS(record_miss, lucent::NoRecord, QueryHit) {
    prd.t = positive_infinity();
    prd.prim = -1;
}

struct AnyHitsRecord {
    BufferView<const float3> origins, directions;
    BufferView<const float> tmin, tmax;
    BufferView<unsigned char> blocked;  // 1: something on the ray in (tmin, tmax)
    Handle mesh;
};
LUCENT_RECORD(AnyHitsRecord, origins, directions, tmin, tmax, blocked, mesh)

LUCENT_RAY_GENERATION(any_hits, AnyHitsRecord) {
    const unsigned i = lucent::launch_index().x;
    lucent::Ray ray;
    const bool blocked =
        batch_ray(RayBatch{rec.origins, rec.directions, rec.tmin, rec.tmax}, i, ray) &&
        lucent::occluded(rec.mesh, ray);
    rec.blocked[i] = blocked ? 1 : 0;
}

}  // namespace lucent_mesh_queries

// ray_query_programs.h: the program module behind lucent.TriangleMesh (python/). Each launch
// index answers one ray of a batch the host copied from numpy arrays into input buffers,
// and writes its answer to output buffers; the same module runs on the CPU backend and,
// compiled by NVRTC into the megakernel, on the GPU.
//   closest_hits: the first surface along each ray (t, triangle, barycentrics, unit normal)
//   any_hits:     is anything on the ray in (tmin, tmax)? (occluded(): no hit program runs)
// A ray with a NaN or infinite origin or direction component, a zero direction, or a NaN
// tmin or tmax, is a miss by definition: it is not traced, so no backend's arithmetic decides what it does.
#pragma once

#include "lucent/device.h"

namespace lucent_python {
// any_hits calls occluded(), so the module declares it.
LUCENT_MODULE(lucent_python_queries, lucent::kUsesOccluded)

using lucent::BufferView;
using lucent::Handle;

constexpr unsigned kQueryRay = 0;  // the one ray type

/// What a closest-hit query's ray carries back (prim -1: nothing hit).
struct QueryHit {
    float t;
    int prim;
    float2 uv;
    float3 normal;
};

/// The bits of a float: the exponent field tells finite from infinite and NaN on every
/// compiler, where x != x does not survive the GPU's fast-math compile.
LUCENT_HD inline unsigned float_bits(float f) {
    union {
        float f;
        unsigned u;
    } bits;
    bits.f = f;
    return bits.u;
}
LUCENT_HD inline bool is_finite(float f) {
    return (float_bits(f) & 0x7f800000u) != 0x7f800000u;
}
LUCENT_HD inline bool is_nan(float f) {
    return (float_bits(f) & 0x7fffffffu) > 0x7f800000u;
}
LUCENT_HD inline float positive_infinity() {
    union {
        unsigned u;
        float f;
    } bits;
    bits.u = 0x7f800000u;
    return bits.f;
}

/// The inputs both queries read: one ray per launch index, and its interval. tmin and tmax
/// hold one value for every ray (count 1) or one per ray.
struct RayBatch {
    BufferView<const float3> origins, directions;
    BufferView<const float> tmin, tmax;
};

/// Ray i of the batch, or false when it is not a ray (see the file's comment). An infinite
/// tmax becomes the engine's "no upper bound".
LUCENT_HD inline bool batch_ray(const RayBatch& batch, unsigned i, lucent::Ray& ray) {
    const float3 o = batch.origins[i], d = batch.directions[i];
    const float tmin = batch.tmin[batch.tmin.count() == 1 ? 0u : i];
    const float tmax = batch.tmax[batch.tmax.count() == 1 ? 0u : i];
    if (!is_finite(o.x) || !is_finite(o.y) || !is_finite(o.z) || !is_finite(d.x) ||
        !is_finite(d.y) || !is_finite(d.z) || is_nan(tmin) || is_nan(tmax))
        return false;
    if (d.x == 0.0f && d.y == 0.0f && d.z == 0.0f) return false;  // no direction
    ray = lucent::make_ray(o, d, kQueryRay, tmin,
                           tmax < lucent::kInfinity ? tmax : lucent::kInfinity);
    return true;
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

}  // namespace lucent_python

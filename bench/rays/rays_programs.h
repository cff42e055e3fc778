// rays_programs.h: the program module of `lucent bench rays --programs`. The ray sets of
// BENCH.md (primary, shadow, diffuse) traced the way a user's programs trace them: each
// launch index reads one ray from input buffers, traces it through the Context's graph and
// writes the answer to output buffers. The same module runs on the CPU backend and, in the
// megakernel, on the GPU; the benchmark compares it with the bare traversal kernels.
//   entry closest_rays (primary and diffuse sets): trace(), the t and triangle of the first hit
//   entry shadow_rays  (shadow set):               occluded(), is anything before the light?
// and the same two with deferred rays, the fastest form on the CPU (see below):
//   entry closest_rays_deferred: trace_deferred() into the output buffer
//   entry shadow_rays_deferred:  occluded_deferred() into the output buffer
//
// Written as the fastest way to write such programs, and why:
//   - The payload is 8 bytes (t, triangle). The payload lives in the ray-generation
//     program's frame and every hit program writes it through a pointer; on the GPU a larger
//     one means more local-memory traffic per ray.
//   - The closest-hit program reads t_hit() and primitive_index() only, never its
//     attributes: on the GPU nothing it does not need is computed for it (the compiler
//     drops the unread attributes). The CPU computes the built-in triangle attributes at
//     the hit regardless, about 18 of a primary ray's 400 time-stamp counts on Sibenik
//     (docs/performance.md).
//   - The miss program writes the "no hit" answer, so the ray-generation program need not
//     initialise the payload before trace() beyond what the miss overwrites.
//   - Shadow rays use occluded(), not trace() with an any-hit program: on a GeometryGroup
//     of triangles it is the BVH's bare any-hit traversal (no frame, no program runs).
//   - No any-hit program is bound, so the closest-hit traversal is the plain one that
//     commits the nearest triangle and computes nothing until the shade phase.
//   - A program that only stores its ray's answer need not wait for it: with
//     trace_deferred() the closest-hit or miss program writes the payload where it lies, in
//     the output buffer, and the CPU traces the rays of many launch indices together as ray
//     streams (1.3-1.8x the single-ray walk on diffuse rays, docs/performance.md). On the
//     GPU they are trace() and occluded().
//   - A ray is two float4s, (origin, tmin) and (direction, tmax), the layout the bare
//     kernels read: two 16-byte loads where three float3/float buffers took seven 4-byte
//     loads from three streams. A closest hit's answer is one 8-byte store (RayHit is
//     8-aligned). Each is read or written once: no read-modify-write of an output.
#pragma once

#include "lucent/device.h"

namespace lucent_bench_rays {
// shadow_rays calls occluded(), so the module declares it.
LUCENT_MODULE(lucent_bench_rays, lucent::kUsesOccluded)

using lucent::BufferView;
using lucent::Handle;

constexpr unsigned kBenchRay = 0;  // the one ray type
constexpr unsigned kNoTriangle = 0xffffffffu;

/// What a closest-hit ray carries back, and what closest_rays writes per ray: t of the
/// first hit (-1: none) and its triangle. 8-aligned, so that it is written in one store.
struct alignas(8) RayHit {
    float t;
    unsigned prim;
};

/// Ray i of a set of rays stored as two float4s each: (origin, tmin), (direction, tmax).
LUCENT_HD inline lucent::Ray ray_at(const BufferView<const float4>& rays, unsigned i) {
    const float4 o = rays[2 * i], d = rays[2 * i + 1];
    return lucent::make_ray(make_float3(o.x, o.y, o.z), make_float3(d.x, d.y, d.z), kBenchRay,
                            o.w, d.w);
}

/// One ray set in, closest hits out.
struct ClosestRaysRecord {
    BufferView<const float4> rays;  // two per ray: (origin, tmin), (direction, tmax)
    BufferView<RayHit> hits;        // t = -1 and prim = kNoTriangle where the ray hits nothing
    Handle scene;
};
LUCENT_RECORD(ClosestRaysRecord, rays, hits, scene)

LUCENT_RAY_GENERATION(closest_rays, ClosestRaysRecord) {
    const unsigned i = lucent::launch_index().x;
    RayHit hit;
    lucent::trace(rec.scene, ray_at(rec.rays, i), hit);
    rec.hits[i] = hit;
}

LUCENT_CLOSEST_HIT(record_hit, lucent::NoRecord, RayHit, lucent::TriangleAttributes) {
    prd.t = lucent::t_hit();
    prd.prim = lucent::primitive_index();
}

LUCENT_MISS(record_miss, lucent::NoRecord, RayHit) {
    prd.t = -1.0f;
    prd.prim = kNoTriangle;
}

/// closest_rays with the ray deferred: the hit programs write its answer straight into
/// the output buffer (the payload is the buffer's element), after this program returns.
LUCENT_RAY_GENERATION(closest_rays_deferred, ClosestRaysRecord) {
    const unsigned i = lucent::launch_index().x;
    lucent::trace_deferred(rec.scene, ray_at(rec.rays, i), rec.hits[i]);
}

/// The shadow set in, one byte per ray out.
struct ShadowRaysRecord {
    BufferView<const float4> rays;      // two per ray, as closest_rays reads them
    BufferView<unsigned char> blocked;  // 1: something between the origin and the light
    Handle scene;
};
LUCENT_RECORD(ShadowRaysRecord, rays, blocked, scene)

LUCENT_RAY_GENERATION(shadow_rays, ShadowRaysRecord) {
    const unsigned i = lucent::launch_index().x;
    rec.blocked[i] = lucent::occluded(rec.scene, ray_at(rec.rays, i)) ? 1 : 0;
}

/// shadow_rays with the ray deferred: the flag is set in the output buffer later.
LUCENT_RAY_GENERATION(shadow_rays_deferred, ShadowRaysRecord) {
    const unsigned i = lucent::launch_index().x;
    lucent::occluded_deferred(rec.scene, ray_at(rec.rays, i), rec.blocked[i]);
}

}  // namespace lucent_bench_rays

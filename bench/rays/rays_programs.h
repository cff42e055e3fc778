// rays_programs.h: the program module of `lucent bench rays --programs`. The ray sets of
// BENCH.md (primary, shadow, diffuse) traced the way a user's programs trace them: each
// launch index reads one ray from input buffers, traces it through the Context's graph and
// writes the answer to output buffers. The same module runs on the CPU backend and, in the
// megakernel, on the GPU; the benchmark compares it with the bare traversal kernels.
//   entry closest_rays (primary and diffuse sets): trace(), the t and triangle of the first hit
//   entry shadow_rays  (shadow set):               occluded(), is anything before the light?
//
// Written as the fastest way to write such programs, and why:
//   - The payload is 8 bytes (t, triangle). The payload lives in the ray-generation
//     program's frame and every hit program writes it through a pointer; on the GPU a larger
//     one means more local-memory traffic per ray.
//   - The closest-hit program reads t_hit() and primitive_index() only, never its
//     attributes: nothing it does not need is computed for it.
//   - The miss program writes the "no hit" answer, so the ray-generation program need not
//     initialise the payload before trace() beyond what the miss overwrites.
//   - Shadow rays use occluded(), not trace() with an any-hit program: on a GeometryGroup
//     of triangles it is the BVH's bare any-hit traversal (no frame, no program runs).
//   - No any-hit program is bound, so the closest-hit traversal is the plain one that
//     commits the nearest triangle and computes nothing until the shade phase.
//   - The rays are structure-of-arrays buffers read once per launch index, and answers are
//     written once: no read-modify-write of an output.
#pragma once

#include "lucent/device.h"

namespace lucent_bench_rays {
// shadow_rays calls occluded(), so the module declares it.
LUCENT_MODULE(lucent_bench_rays, lucent::kUsesOccluded)

using lucent::BufferView;
using lucent::Handle;

constexpr unsigned kBenchRay = 0;  // the one ray type
constexpr unsigned kNoTriangle = 0xffffffffu;

/// What a closest-hit ray carries back: t of the first hit (-1: none) and its triangle.
struct RayHit {
    float t;
    unsigned prim;
};

/// One ray set in, closest hits out (tmin is 0 for every BENCH.md ray).
struct ClosestRaysRecord {
    BufferView<const float3> origins, directions;
    BufferView<const float> tmax;
    BufferView<float> t;          // -1 where the ray hits nothing
    BufferView<unsigned> prim;    // kNoTriangle where it hits nothing
    Handle scene;
};
LUCENT_RECORD(ClosestRaysRecord, origins, directions, tmax, t, prim, scene)

LUCENT_RAY_GENERATION(closest_rays, ClosestRaysRecord) {
    const unsigned i = lucent::launch_index().x;
    RayHit hit;
    lucent::trace(rec.scene,
                  lucent::make_ray(rec.origins[i], rec.directions[i], kBenchRay, 0.0f, rec.tmax[i]),
                  hit);
    rec.t[i] = hit.t;
    rec.prim[i] = hit.prim;
}

LUCENT_CLOSEST_HIT(record_hit, lucent::NoRecord, RayHit, lucent::TriangleAttributes) {
    prd.t = lucent::t_hit();
    prd.prim = lucent::primitive_index();
}

LUCENT_MISS(record_miss, lucent::NoRecord, RayHit) {
    prd.t = -1.0f;
    prd.prim = kNoTriangle;
}

/// The shadow set in, one byte per ray out.
struct ShadowRaysRecord {
    BufferView<const float3> origins, directions;
    BufferView<const float> tmax;
    BufferView<unsigned char> blocked;  // 1: something between the origin and the light
    Handle scene;
};
LUCENT_RECORD(ShadowRaysRecord, origins, directions, tmax, blocked, scene)

LUCENT_RAY_GENERATION(shadow_rays, ShadowRaysRecord) {
    const unsigned i = lucent::launch_index().x;
    const bool blocked = lucent::occluded(
        rec.scene,
        lucent::make_ray(rec.origins[i], rec.directions[i], kBenchRay, 0.0f, rec.tmax[i]));
    rec.blocked[i] = blocked ? 1 : 0;
}

}  // namespace lucent_bench_rays

// Programs of deferred_rays_test: the shared caster and the occlusion queries with their
// rays deferred (trace_deferred(), occluded_deferred()), a caster that wrongly defers into
// a local, and hit programs that show which launch index their ray came from.
#pragma once

#include "tests/programs/common.h"
#include "tests/programs/occlusion_programs.h"

namespace lucent_tests {
// Each test module in its own inline namespace: its own LUCENT_MODULE, while the tests
// still name its programs and types unqualified.
inline namespace deferred_module {
LUCENT_MODULE(test_deferred, lucent::kUsesOccluded)

/// common_cast with the ray deferred: the payload starts in the results buffer, where the
/// closest-hit or miss program later writes it.
LUCENT_RAY_GENERATION(deferred_cast, CasterRecord) {
    const unsigned i = launch_index().x;
    const CastRay r = rec.rays[i];
    rec.results[i] = make_test_payload();
    trace_deferred(rec.top, make_ray(r.origin, r.direction, 0, 1e-4f), rec.results[i]);
}

/// Each ray twice in one launch (so that on the GPU both see the same tree): deferred into
/// results, waited for into waited.
struct BesideRecord {
    Handle top;
    BufferView<CastRay> rays;
    BufferView<TestPayload> results;
    BufferView<TestPayload> waited;
};
LUCENT_RECORD(BesideRecord, top, rays, results, waited)
LUCENT_RAY_GENERATION(deferred_beside_trace, BesideRecord) {
    const unsigned i = launch_index().x;
    const CastRay r = rec.rays[i];
    const Ray ray = make_ray(r.origin, r.direction, 0, 1e-4f);
    rec.results[i] = make_test_payload();
    trace_deferred(rec.top, ray, rec.results[i]);
    TestPayload p = make_test_payload();
    trace(rec.top, ray, p);
    rec.waited[i] = p;
}

/// Wrong: the payload is the program's local, gone when the ray is traced.
LUCENT_RAY_GENERATION(deferred_cast_into_local, CasterRecord) {
    const unsigned i = launch_index().x;
    const CastRay r = rec.rays[i];
    TestPayload p = make_test_payload();
    trace_deferred(rec.top, make_ray(r.origin, r.direction, 0, 1e-4f), p);
    rec.results[i] = p;
}

/// Wrong at the last launch index alone (its payload a local): the launch fails late, while
/// the other indices' rays are queued and traced.
LUCENT_RAY_GENERATION(deferred_cast_last_into_local, CasterRecord) {
    const unsigned i = launch_index().x;
    const CastRay r = rec.rays[i];
    rec.results[i] = make_test_payload();
    if (i + 1 < launch_size().x) {
        trace_deferred(rec.top, make_ray(r.origin, r.direction, 0, 1e-4f), rec.results[i]);
        return;
    }
    TestPayload p = make_test_payload();
    trace_deferred(rec.top, make_ray(r.origin, r.direction, 0, 1e-4f), p);
    rec.results[i] = p;
}

/// Two rays a launch index, both deferred: along the ray into results, back into backward.
struct BothWaysRecord {
    Handle top;
    BufferView<CastRay> rays;
    BufferView<TestPayload> results;
    BufferView<TestPayload> backward;
};
LUCENT_RECORD(BothWaysRecord, top, rays, results, backward)
LUCENT_RAY_GENERATION(deferred_cast_both_ways, BothWaysRecord) {
    const unsigned i = launch_index().x;
    const CastRay r = rec.rays[i];
    rec.results[i] = make_test_payload();
    rec.backward[i] = make_test_payload();
    trace_deferred(rec.top, make_ray(r.origin, r.direction, 0, 1e-4f), rec.results[i]);
    trace_deferred(rec.top, make_ray(r.origin, -r.direction, 0, 1e-4f), rec.backward[i]);
}

/// Each query twice in one launch: occluded() into occluded, occluded_deferred() into deferred.
struct OcclusionBesideRecord {
    Handle top;
    BufferView<OcclusionQuery> queries;
    BufferView<unsigned> occluded;
    BufferView<unsigned> deferred;
};
LUCENT_RECORD(OcclusionBesideRecord, top, queries, occluded, deferred)
LUCENT_RAY_GENERATION(deferred_beside_occluded, OcclusionBesideRecord) {
    const unsigned i = launch_index().x;
    const OcclusionQuery q = rec.queries[i];
    const Ray ray = make_ray(q.origin, q.direction, 0, 1e-4f, q.tmax);
    const Occlusion test = q.leaf_boxes ? Occlusion::kLeafBoxes : Occlusion::kExact;
    occluded_deferred(rec.top, ray, rec.deferred[i], test);
    rec.occluded[i] = occluded(rec.top, ray, test) ? 1u : 0u;
}

/// Closest hit: the launch index that deferred the ray (in `id`), and code A (detail = the
/// index) for odd indices, after writing the payload.
LUCENT_CLOSEST_HIT(deferred_index_hit, NoRecord, TestPayload, TriangleAttributes) {
    prd.hit = 1;
    prd.id = launch_index().x;
    prd.t = t_hit();
    if (launch_index().x % 2 == 1) throw_exception(kUserExceptionBase + 7, launch_index().x);
}

/// Closest hit that defers a second ray onward from the hit (not from a ray-generation
/// program: it is traced at once) and says in anyhit_count whether it hit something.
struct OnwardRecord {
    Handle top;
    BufferView<TestPayload> onward;  // the second ray's payload per launch index
};
LUCENT_RECORD(OnwardRecord, top, onward)
LUCENT_CLOSEST_HIT(deferred_onward_hit, OnwardRecord, TestPayload, TriangleAttributes) {
    prd.hit = 1;
    prd.t = t_hit();
    const unsigned i = launch_index().x;
    rec.onward[i] = make_test_payload();
    const Ray& ray = current_ray();
    const float3 at = ray.origin + t_hit() * ray.direction;
    trace_deferred(rec.top, make_ray(at, ray.direction, 0, 1e-3f), rec.onward[i]);
    // Traced at once: its answer is there already.
    prd.anyhit_count = rec.onward[i].hit == 1 ? 1u : 0u;
}

}  // namespace deferred_module
}  // namespace lucent_tests

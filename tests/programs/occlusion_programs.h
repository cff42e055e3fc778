// Programs of the occlusion-query tests: a ray generation that asks lucent::occluded() for
// each listed ray segment, an any-hit that ignores every intersection (which occluded() must
// never run), and one that counts them.
#pragma once

#include "tests/programs/common.h"

namespace lucent_tests {
// Each test module in its own inline namespace: its own LUCENT_MODULE, while the tests
// still name its programs and types unqualified.
inline namespace occlusion_module {
LUCENT_MODULE(test_occlusion, lucent::kUsesOccluded)

struct OcclusionQuery {
    float3 origin, direction;
    float tmax;
    unsigned leaf_boxes;  // 1: occluded(..., Occlusion::kLeafBoxes)
};

struct OcclusionRecord {
    Handle top;
    BufferView<OcclusionQuery> queries;
    BufferView<unsigned> occluded;   // 1: something in (tmin, tmax); 0: nothing
    BufferView<TestPayload> traced;  // the same segment through trace(), for comparison
};
LUCENT_RECORD(OcclusionRecord, top, queries, occluded, traced)

LUCENT_RAY_GENERATION(occlusion_cast, OcclusionRecord) {
    const unsigned i = launch_index().x;
    const OcclusionQuery q = rec.queries[i];
    const Ray ray = make_ray(q.origin, q.direction, 0, 1e-4f, q.tmax);
    const Occlusion test = q.leaf_boxes ? Occlusion::kLeafBoxes : Occlusion::kExact;
    rec.occluded[i] = occluded(rec.top, ray, test) ? 1u : 0u;
    TestPayload p = make_test_payload();
    trace(rec.top, ray, p);
    rec.traced[i] = p;
}

LUCENT_ANY_HIT(occlusion_ignore_all, NoRecord, TestPayload, TriangleAttributes) {
    ++prd.anyhit_count;
    ignore_intersection();
}

// Counts the intersections and accepts them (tree_upgrade_test).
LUCENT_ANY_HIT(occlusion_count_all, NoRecord, TestPayload, TriangleAttributes) {
    ++prd.anyhit_count;
}

}  // namespace occlusion_module
}  // namespace lucent_tests

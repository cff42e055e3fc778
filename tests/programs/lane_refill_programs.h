// Programs of the lane refill test (tests/lane_refill_test.cpp): a ray generation that traces
// none, one or two rays, by its launch index, so that a warp's lanes finish their traces at
// different times and come back to trace() different numbers of times.
#pragma once

#include "tests/programs/common.h"

namespace lucent_tests {
// Each test module in its own inline namespace: its own LUCENT_MODULE, while the tests
// still name its programs and types unqualified.
inline namespace lane_refill_module {
LUCENT_MODULE(test_lane_refill)

struct RefillRay {
    float3 origin, direction;
    float tmax;
};

struct RefillRecord {
    Handle top;
    BufferView<RefillRay> rays;        // two a launch index
    BufferView<unsigned> trace_count;  // 0, 1 or 2 a launch index
    BufferView<TestPayload> traced;    // two a launch index: what each trace found
};
LUCENT_RECORD(RefillRecord, top, rays, trace_count, traced)

LUCENT_RAY_GENERATION(refill_cast, RefillRecord) {
    const uint3 index = launch_index();
    const unsigned i = index.y * launch_size().x + index.x;
    for (unsigned k = 0; k < rec.trace_count[i]; ++k) {
        const RefillRay r = rec.rays[2 * i + k];
        TestPayload p = make_test_payload();
        trace(rec.top, make_ray(r.origin, r.direction, 0, 1e-4f, r.tmax), p);
        rec.traced[2 * i + k] = p;
    }
}

}  // namespace lane_refill_module
}  // namespace lucent_tests

// Programs of validation_test: deliberately mismatched payloads, a record with a float3
// field, and a 2D image writer for the output-size check.
#pragma once

#include "tests/programs/common.h"

namespace lucent_tests {
// Each test module in its own inline namespace: its own LUCENT_MODULE, while the tests
// still name its programs and types unqualified.
inline namespace validation_module {
LUCENT_MODULE(test_validation)

/// A payload that is not the radiance ray type's.
struct OtherPayload {
    float value;
};

LUCENT_MISS(vat_miss_other, NoRecord, OtherPayload) {
    prd.value = 0;
}
LUCENT_CLOSEST_HIT(vat_closest_other, NoRecord, OtherPayload, TriangleAttributes) {
    prd.value = t_hit();
}

LUCENT_ANY_HIT(vat_anyhit_count, NoRecord, TestPayload, TriangleAttributes) {
    prd.anyhit_count += 1;
}

struct ShadeRecord {
    float3 kd;
};
LUCENT_RECORD(ShadeRecord, kd)
LUCENT_CLOSEST_HIT(vat_shade, ShadeRecord, TestPayload, TriangleAttributes) {
    prd.hit = 1;
    prd.point = rec.kd;
}

struct ImageRecord {
    BufferView<float> image;
};
LUCENT_RECORD(ImageRecord, image)
/// Writes only inside the buffer: if the engine failed to reject a wrong-sized output
/// buffer, the test fails on its expectation instead of corrupting memory.
LUCENT_RAY_GENERATION(vat_write_image, ImageRecord) {
    const uint3 i = launch_index();
    if (i.x < rec.image.size.x && i.y < rec.image.size.y) rec.image[make_uint2(i.x, i.y)] = 1.0f;
}

// ---- callables of mismatched signatures ----------------------------------------------
struct CallFloatRecord {
    Callable<float(float)> fn;
};
LUCENT_RECORD(CallFloatRecord, fn)
LUCENT_RAY_GENERATION(vat_call_float, CallFloatRecord) {
    (void)rec.fn(1.0f);
}

LUCENT_CALLABLE(vat_callable_float3, NoRecord, float3, (float3 v)) {
    return v;
}
LUCENT_CALLABLE(vat_callable_float, NoRecord, float, (float v)) {
    return v;
}

}  // namespace validation_module
}  // namespace lucent_tests

// Programs of the soak test (soak_test): an orthographic camera whose rays run along +z
// from every pixel centre, closest hits that report their material's id (one of them
// shifted, so that a program swap shows in the image) and a miss that reports the
// background's.
#pragma once

#include "tests/programs/common.h"

namespace lucent_tests {
inline namespace soak_module {
LUCENT_MODULE(test_soak)

struct SoakPayload {
    unsigned id;
};

struct SoakCameraRecord {
    Handle top;
    BufferView<unsigned> image;  // width x height ids, row-major
    unsigned width;
};
LUCENT_RECORD(SoakCameraRecord, top, image, width)

/// Pixel (x, y)'s ray starts at (x + 0.5, y + 0.5, -10) and runs along +z.
LUCENT_RAY_GENERATION(soak_camera, SoakCameraRecord) {
    const uint3 i = launch_index();
    SoakPayload p{0xffffffffu};
    trace(rec.top,
          make_ray(make_float3(float(i.x) + 0.5f, float(i.y) + 0.5f, -10.0f),
                   make_float3(0.0f, 0.0f, 1.0f), 0, 1e-4f),
          p);
    rec.image[i.y * rec.width + i.x] = p.id;
}

struct SoakBackgroundRecord {
    unsigned background;
};
LUCENT_RECORD(SoakBackgroundRecord, background)
LUCENT_MISS(soak_miss, SoakBackgroundRecord, SoakPayload) {
    prd.id = rec.background;
}

LUCENT_CLOSEST_HIT(soak_triangle_hit, IdRecord, SoakPayload, TriangleAttributes) {
    prd.id = rec.id;
}
/// The same with 100000 added: which of the two a material has is visible in the image.
LUCENT_CLOSEST_HIT(soak_triangle_hit_shifted, IdRecord, SoakPayload, TriangleAttributes) {
    prd.id = rec.id + 100000u;
}
LUCENT_CLOSEST_HIT(soak_sphere_hit, IdRecord, SoakPayload, SphereAttributes) {
    prd.id = rec.id;
}

}  // namespace soak_module
}  // namespace lucent_tests

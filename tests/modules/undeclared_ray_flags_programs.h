// A module that passes ray flags to occluded() without declaring kUsesRayFlags
// (modules_test): the CPU refuses the call as the GPU's compile does.
#pragma once

#include "lucent/device.h"

namespace undeclared_ray_flags {
LUCENT_MODULE(test_undeclared_ray_flags, lucent::kUsesOccluded)

struct ShadowRecord {
    lucent::Handle top;
    lucent::BufferView<unsigned> out;
};
LUCENT_RECORD(ShadowRecord, top, out)

LUCENT_RAY_GENERATION(culling_probe, ShadowRecord) {
    const unsigned i = lucent::launch_index().x;
    const lucent::Ray ray = lucent::make_ray(make_float3(0, 0, 0), make_float3(0, 0, 1), 0, 0.0f);
    rec.out[i] = lucent::occluded(rec.top, ray, lucent::Occlusion::kExact,
                                  lucent::kRayFlagCullBackFacingTriangles)
                     ? 1u
                     : 0u;
}
}  // namespace undeclared_ray_flags

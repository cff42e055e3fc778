// A module that calls occluded() without declaring kUsesOccluded (modules_test): the CPU
// refuses the call as the GPU's compile does.
#pragma once

#include "lucent/device.h"

namespace undeclared_occlusion {
LUCENT_MODULE(test_undeclared_occlusion)

struct ShadowRecord {
    lucent::Handle top;
    lucent::BufferView<unsigned> out;
};
LUCENT_RECORD(ShadowRecord, top, out)

LUCENT_RAY_GENERATION(shadow_probe, ShadowRecord) {
    const unsigned i = lucent::launch_index().x;
    const lucent::Ray ray = lucent::make_ray(make_float3(0, 0, 0), make_float3(0, 0, 1), 0, 0.0f);
    rec.out[i] = lucent::occluded(rec.top, ray) ? 1u : 0u;
}
}  // namespace undeclared_occlusion

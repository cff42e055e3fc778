// The light sources of scene::Scene as the samples' programs read them from buffers.
#pragma once

#include "lucent/device.h"

namespace sample_common {

struct PointLight {
    float3 position;
    float3 intensity;
};

/// An emitting parallelogram corner + s edge1 + t edge2 (s, t in [0, 1]); it emits on the
/// side cross(edge1, edge2) points to (scene::AreaLight).
struct AreaLight {
    float3 corner, edge1, edge2;
    float3 emission;
};

}  // namespace sample_common

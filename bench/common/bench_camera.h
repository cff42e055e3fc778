// The viewpoint of a benchmark scene: a line of cameras.txt beside the scene or one
// directory up (../shared/scenes/cameras.txt), as shared/BENCH.md defines its ray sets.
#pragma once

#include <string>

#include "lucent/device/vector_math.h"

namespace lucent::bench {

struct Camera {
    float3 eye, look, up;
    float fov;
    float3 light;
};

/// The scene's viewpoint; throws lucent::Error naming cameras.txt:line for a bad line, or
/// the scene and the flags to pass when there is none.
Camera find_camera(const std::string& scene);

}  // namespace lucent::bench

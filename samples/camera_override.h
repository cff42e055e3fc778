// The camera a render is asked for in place of its scene's (`lucent render --eye --look
// --up --fov`, lucent.render(eye=..., ...)): any of the four, the rest from the scene.
#pragma once

#include <optional>

#include "scene/scene.h"

namespace lucent::samples {

struct CameraOverride {
    std::optional<float3> eye, look, up;
    std::optional<float> fov_degrees;  // vertical

    bool empty() const { return !eye && !look && !up && !fov_degrees; }

    /// `camera` with the given parts replaced. Throws SettingsError for a camera that cannot
    /// see: a non-finite value, the eye at the look-at point, an up along the view direction,
    /// a field of view outside (0, 180) degrees.
    scene::Camera applied_to(scene::Camera camera) const;
};

}  // namespace lucent::samples

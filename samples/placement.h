// Where a sample puts its built-in scene: a similarity transform p -> scale * p + offset of
// geometry, lights and camera alike, so a test can render the same scene modelled in
// micrometres or kilometres, or far from the origin, and compare it with the scene as
// modelled (tests/scale_test.cpp). Computed in double and rounded once, as a modelling tool
// would write the moved scene.
#pragma once

#include "lucent/device/types.h"
#include "scene/scene.h"

namespace lucent::samples {

struct Placement {
    double scale = 1;
    double offset = 0;  // added to x, y and z alike

    float3 point(float3 p) const {
        return make_float3(float(scale * p.x + offset), float(scale * p.y + offset),
                           float(scale * p.z + offset));
    }
    float3 vector(float3 v) const {
        return make_float3(float(scale * v.x), float(scale * v.y), float(scale * v.z));
    }
    /// A length (a radius, a march step).
    float length(float l) const { return float(scale * l); }
    /// A quantity per unit length (an extinction coefficient): the same amount per object.
    float per_length(float k) const { return float(k / scale); }
    /// A point light's intensity: its irradiance, I / d^2, stays the same at every scale.
    float3 intensity(float3 i) const { return i * float(scale * scale); }
    /// Eye and look moved; up and field of view kept.
    scene::Camera camera(scene::Camera c) const {
        c.eye = point(c.eye);
        c.look = point(c.look);
        return c;
    }
};

}  // namespace lucent::samples

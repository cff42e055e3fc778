// The bounds of a scene and the camera that frames them, for scenes that bring no camera;
// whether a camera's up leaves its image an orientation.
#include <algorithm>
#include <cmath>

#include "lucent/error.h"
#include "scene/scene.h"

namespace lucent::scene {

Bounds scene_bounds(const Scene& scene) {
    Bounds b{make_float3(1e30f), make_float3(-1e30f)};
    for (const Instance& instance : drawn_instances(scene))
        for (const float3& p : scene.meshes[instance.mesh].positions) {
            const float3 w = transform_point(instance.transform, p);
            b.lo = fminf(b.lo, w);
            b.hi = fmaxf(b.hi, w);
        }
    return b;
}

Camera framing_camera(const Scene& scene) {
    if (scene.drawn_triangle_count() == 0)
        throw Error("framing_camera: scene '" + scene.name + "' has no triangles to frame");
    const Bounds b = scene_bounds(scene);
    const float3 centre = 0.5f * (b.lo + b.hi);
    const float radius = std::max(0.5f * length(b.hi - b.lo), 1e-6f);
    // The bounding sphere fits the 45-degree vertical field of view from 2.8 radii away
    // (sin 22.5 degrees = 0.38 > 1 / 2.8), in front of the +z face.
    return Camera{centre + make_float3(0, 0, 2.8f * radius), centre, {0, 1, 0}, 45};
}

bool up_along_view(const Camera& c) {
    const float3 view = c.look - c.eye;
    const float distance = length(view), up_length = length(c.up);
    return !(up_length > 0.0f) || !(length(cross(view / distance, c.up / up_length)) >= 1e-3f);
}

}  // namespace lucent::scene

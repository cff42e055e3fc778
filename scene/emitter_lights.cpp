// Emissive triangles as area lights: what lights an OBJ scene (its MTL's Ke) or a JSON
// scene's emitting materials, for every sample's light sampling.
#include <algorithm>
#include <cmath>

#include "scene/scene.h"

namespace lucent::scene {

namespace {

/// Whether point c lies on the light: within `tolerance` of its plane and inside its
/// parallelogram (or triangle).
bool lies_on(const AreaLight& light, float3 c, float tolerance) {
    const float3 normal = cross(light.edge1, light.edge2);
    const float area2 = dot(normal, normal);
    if (!(area2 > 0)) return false;
    const float3 w = c - light.corner;
    const float a = dot(cross(w, light.edge2), normal) / area2;
    const float b = dot(cross(light.edge1, w), normal) / area2;
    const bool inside = light.triangle ? a >= 0 && b >= 0 && a + b <= 1
                                       : a >= 0 && a <= 1 && b >= 0 && b <= 1;
    return std::fabs(dot(w, normal)) / std::sqrt(area2) <= tolerance && inside;
}

float3 centroid(const Mesh& mesh, size_t t) {
    const uint3 v = mesh.indices[t];
    return (mesh.positions[v.x] + mesh.positions[v.y] + mesh.positions[v.z]) / 3.0f;
}

/// Distances below which two surfaces count as one: a thousandth of the scene's size.
float coincidence_tolerance(const Scene& scene) {
    const Bounds b = scene_bounds(scene);
    return 1e-3f * std::max({std::fabs(b.lo.x), std::fabs(b.lo.y), std::fabs(b.lo.z),
                             std::fabs(b.hi.x), std::fabs(b.hi.y), std::fabs(b.hi.z), 1e-3f});
}

}  // namespace

bool has_emitting_geometry(const Scene& s, const AreaLight& light, float tolerance) {
    for (const Mesh& mesh : s.meshes)
        for (size_t t = 0; t < mesh.indices.size(); ++t)
            if (max_component(s.materials[mesh.materials[t]].emission) > 0 &&
                lies_on(light, centroid(mesh, t), tolerance))
                return true;
    return false;
}

std::vector<AreaLight> emitter_lights(const Scene& s) {
    std::vector<AreaLight> lights = s.area_lights;
    const float tolerance = coincidence_tolerance(s);
    for (const Mesh& mesh : s.meshes)
        for (size_t t = 0; t < mesh.indices.size(); ++t) {
            const float3 emission = s.materials[mesh.materials[t]].emission;
            if (!(max_component(emission) > 0)) continue;
            const uint3 v = mesh.indices[t];
            const float3 p0 = mesh.positions[v.x], e1 = mesh.positions[v.y] - p0,
                         e2 = mesh.positions[v.z] - p0;
            if (!(length(cross(e1, e2)) > 0)) continue;  // degenerate: no area, no light
            const float3 c = centroid(mesh, t);
            if (std::any_of(s.area_lights.begin(), s.area_lights.end(),
                            [&](const AreaLight& l) { return lies_on(l, c, tolerance); }))
                continue;
            lights.push_back(AreaLight{p0, e1, e2, emission, /*triangle=*/true});
        }
    return lights;
}

bool has_lights(const Scene& s) {
    if (!s.point_lights.empty() || !s.area_lights.empty()) return true;
    for (const Mesh& mesh : s.meshes)
        for (unsigned m : mesh.materials)
            if (max_component(s.materials[m].emission) > 0) return true;
    return false;
}

}  // namespace lucent::scene

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

/// Triangle t of a mesh where an instance draws it: lights live in world space, so an
/// instanced emitter is one light per instance, of the area its transform gives it.
struct WorldTriangle {
    float3 p0, p1, p2;
    float3 centroid() const { return (p0 + p1 + p2) / 3.0f; }
};
WorldTriangle world_triangle(const Mesh& mesh, const Instance& instance, size_t t) {
    const uint3 v = mesh.indices[t];
    return {transform_point(instance.transform, mesh.positions[v.x]),
            transform_point(instance.transform, mesh.positions[v.y]),
            transform_point(instance.transform, mesh.positions[v.z])};
}

/// Distances below which two surfaces count as one: a thousandth of the scene's size.
float coincidence_tolerance(const Scene& scene) {
    const Bounds b = scene_bounds(scene);
    return 1e-3f * std::max({std::fabs(b.lo.x), std::fabs(b.lo.y), std::fabs(b.lo.z),
                             std::fabs(b.hi.x), std::fabs(b.hi.y), std::fabs(b.hi.z), 1e-3f});
}

}  // namespace

bool has_emitting_geometry(const Scene& s, const AreaLight& light, float tolerance) {
    for (const Instance& instance : drawn_instances(s)) {
        const Mesh& mesh = s.meshes[instance.mesh];
        for (size_t t = 0; t < mesh.indices.size(); ++t)
            if (max_component(s.materials[mesh.materials[t]].emission) > 0 &&
                lies_on(light, world_triangle(mesh, instance, t).centroid(), tolerance))
                return true;
    }
    return false;
}

std::vector<AreaLight> emitter_lights(const Scene& s) {
    std::vector<AreaLight> lights = s.area_lights;
    const float tolerance = coincidence_tolerance(s);
    for (const Instance& instance : drawn_instances(s)) {
        const Mesh& mesh = s.meshes[instance.mesh];
        for (size_t t = 0; t < mesh.indices.size(); ++t) {
            const float3 emission = s.materials[mesh.materials[t]].emission;
            if (!(max_component(emission) > 0)) continue;
            const WorldTriangle w = world_triangle(mesh, instance, t);
            const float3 p0 = w.p0, e1 = w.p1 - p0, e2 = w.p2 - p0;
            if (!(length(cross(e1, e2)) > 0)) continue;  // degenerate: no area, no light
            const float3 c = w.centroid();
            if (std::any_of(s.area_lights.begin(), s.area_lights.end(),
                            [&](const AreaLight& l) { return lies_on(l, c, tolerance); }))
                continue;
            lights.push_back(AreaLight{p0, e1, e2, emission, /*triangle=*/true});
        }
    }
    return lights;
}

bool has_lights(const Scene& s) {
    if (!s.point_lights.empty() || !s.area_lights.empty()) return true;
    for (const Instance& instance : drawn_instances(s))
        for (unsigned m : s.meshes[instance.mesh].materials)
            if (max_component(s.materials[m].emission) > 0) return true;
    return false;
}

}  // namespace lucent::scene

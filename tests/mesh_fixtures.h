// Triangle meshes several test suites build their scenes from (the CPU accel's tests, the GPU
// layout's, the engine's), so that a case written once reads the same everywhere.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "lucent/device/triangle_intersect.h"
#include "lucent/device/vector_math.h"

namespace lucent::test_meshes {

/// Triangles as the engine takes them: vertices and one index triple per triangle.
struct Mesh {
    std::vector<float3> positions;
    std::vector<uint3> indices;
};

/// A floor of two big triangles (z = 0, [0, 10]^2) under `count` small ones up to z = 0.7:
/// the floor overlaps everything, so object splits cannot separate it and spatial splits
/// pay (the case of Sponza's floors).
inline Mesh floor_and_clutter(uint32_t seed, int count) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    Mesh m;
    m.positions = {make_float3(0, 0, 0), make_float3(10, 0, 0), make_float3(10, 10, 0),
                   make_float3(0, 10, 0)};
    m.indices = {make_uint3(0, 1, 2), make_uint3(0, 2, 3)};
    for (int i = 0; i < count; ++i) {
        const float3 a = make_float3(10 * uni(rng), 10 * uni(rng), 0.5f * uni(rng));
        const uint32_t base = (uint32_t)m.positions.size();
        m.positions.insert(m.positions.end(), {a, a + make_float3(0.2f * uni(rng), 0.1f, 0.0f),
                                               a + make_float3(0.0f, 0.2f * uni(rng), 0.2f)});
        m.indices.push_back(make_uint3(base, base + 1, base + 2));
    }
    return m;
}

/// Brute force's nearest hit of the ray o + t d with t in (tmin, tmax) among the mesh's
/// triangles (the watertight test the engine uses), or infinity.
inline float nearest_hit(const Mesh& mesh, float3 o, float3 d, float tmin, float tmax) {
    const WatertightRay wt = make_watertight_ray(o, d);
    float nearest = INFINITY;
    for (const uint3 tri : mesh.indices) {
        float t, b1, b2;
        if (intersect_triangle_watertight(wt, mesh.positions[tri.x], mesh.positions[tri.y],
                                          mesh.positions[tri.z], tmin, tmax, t, b1, b2))
            nearest = std::min(nearest, t);
    }
    return nearest;
}

}  // namespace lucent::test_meshes

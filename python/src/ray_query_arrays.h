// The arrays of one lucent.TriangleMesh query as the engine side sees them: flat float and
// int arrays that the binding (mesh_binding.cpp) checked, rays in and answers out.
#pragma once

#include <cstddef>
#include <cstdint>

namespace lucent::python {

/// A batch of rays as flat arrays: origins and directions are count x 3 floats; tmin and
/// tmax hold 1 value (for every ray) or `count`.
struct RayArrays {
    const float* origins = nullptr;
    const float* directions = nullptr;
    const float* tmin = nullptr;
    size_t tmin_count = 1;
    const float* tmax = nullptr;
    size_t tmax_count = 1;
    size_t count = 0;
};

/// Where intersect() writes: count values of t, prim; count x 2 of uv; count x 3 of normal.
struct HitArrays {
    float* t = nullptr;
    int32_t* prim = nullptr;
    float* uv = nullptr;
    float* normal = nullptr;
};

}  // namespace lucent::python

// Meshes, rays and a brute-force reference for the GPU triangle BVH tests (the layout's
// CPU traversal, and the GPU builder): the cases where a careless box test loses hits.
#pragma once

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "cuda/device/lucent_gpu/triangle_bvh.cuh"
#include "lucent/device/triangle_intersect.h"
#include "tests/mesh_fixtures.h"

namespace lucent::test_meshes {

using gpu::GpuHit;

/// Triangles: random small ones, plus an axis-aligned grid of quads (shared edges, flat
/// boxes), the cases where a careless box test loses hits.
inline Mesh test_mesh(unsigned seed, int random_count) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(0.0f, 10.0f), off(-0.6f, 0.6f);
    Mesh m;
    for (int i = 0; i < random_count; ++i) {
        const float3 c = make_float3(pos(rng), pos(rng), pos(rng));
        const unsigned base = (unsigned)m.positions.size();
        for (int v = 0; v < 3; ++v)
            m.positions.push_back(c + make_float3(off(rng), off(rng), off(rng)));
        m.indices.push_back(make_uint3(base, base + 1, base + 2));
    }
    // A 12 x 12 grid of quads in the plane z = 5 and one in x = 2 (indexed, shared vertices).
    for (int plane = 0; plane < 2; ++plane) {
        const unsigned base = (unsigned)m.positions.size();
        for (int j = 0; j <= 12; ++j)
            for (int i = 0; i <= 12; ++i) {
                const float a = i * (10.0f / 12), b = j * (10.0f / 12);
                m.positions.push_back(plane == 0 ? make_float3(a, b, 5.0f)
                                                 : make_float3(2.0f, a, b));
            }
        for (int j = 0; j < 12; ++j)
            for (int i = 0; i < 12; ++i) {
                const unsigned v = base + j * 13 + i;
                m.indices.push_back(make_uint3(v, v + 1, v + 14));
                m.indices.push_back(make_uint3(v, v + 14, v + 13));
            }
    }
    return m;
}

struct Brute {
    const Mesh& m;
    /// Closest hit among triangles with accept(prim), or t < 0.
    template <class Accept>
    GpuHit closest(float3 o, float3 d, float tmin, float tmax, Accept&& accept) const {
        const WatertightRay r = make_watertight_ray(o, d);
        GpuHit best{-1.0f, 0, 0, 0};
        float limit = tmax;
        for (size_t i = 0; i < m.indices.size(); ++i) {
            if (!accept((unsigned)i)) continue;
            const uint3 t = m.indices[i];
            float th, u, v;
            if (intersect_triangle_watertight(r, m.positions[t.x], m.positions[t.y],
                                              m.positions[t.z], tmin, limit, th, u, v)) {
                limit = th;
                best = GpuHit{th, u, v, (unsigned)i};
            }
        }
        return best;
    }
    float t_of(unsigned prim, float3 o, float3 d) const {
        const WatertightRay r = make_watertight_ray(o, d);
        const uint3 t = m.indices[prim];
        float th = -1, u, v;
        if (!intersect_triangle_watertight(r, m.positions[t.x], m.positions[t.y], m.positions[t.z],
                                           -kInfinity, kInfinity, th, u, v))
            return -1.0f;
        return th;
    }
};

struct TestRay {
    float3 o, d;
    float tmax;
};

inline std::vector<TestRay> test_rays(unsigned seed, int count) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(-1.0f, 11.0f), dir(-1.0f, 1.0f), len(0.5f, 20.0f);
    std::vector<TestRay> rays;
    for (int i = 0; i < count; ++i) {
        float3 d = make_float3(dir(rng), dir(rng), dir(rng));
        // Some axis-aligned directions (zero components: infinite 1/d) and exact grid
        // points as origins (0 * inf in the slab test).
        if (i % 7 == 0) d.x = 0.0f;
        if (i % 11 == 0) d.y = 0.0f, d.z = i % 22 == 0 ? 1.0f : -1.0f;
        if (dot(d, d) == 0.0f) d = make_float3(0, 0, 1);
        float3 o = make_float3(pos(rng), pos(rng), pos(rng));
        if (i % 13 == 0) o = make_float3(2.0f, 10.0f / 12 * 3, 10.0f / 12 * 5);
        rays.push_back({o, normalize(d), i % 3 == 0 ? len(rng) : kInfinity});
    }
    return rays;
}

inline void expect_same_closest(const Brute& brute, const TestRay& r, bool gpu_hit, const GpuHit& g,
                                const GpuHit& b, int index) {
    ASSERT_EQ(gpu_hit, b.t >= 0.0f) << "ray " << index;
    if (!gpu_hit) return;
    EXPECT_EQ(g.t, b.t) << "ray " << index;
    if (g.prim != b.prim) {  // a tie: the reported triangle must be hit at the same t
        EXPECT_EQ(brute.t_of(g.prim, r.o, r.d), b.t) << "ray " << index;
    } else {
        EXPECT_TRUE(g.u == b.u && g.v == b.v) << "ray " << index;
    }
}

}  // namespace lucent::test_meshes

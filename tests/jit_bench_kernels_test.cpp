// The bench kernels compile with NVRTC, and the GPU triangle BVH layout, traversed on the
// CPU by the very code the GPU runs (triangle_bvh.cuh is host/device), finds the same
// hits as brute force and as TriangleAccel (ARCHITECTURE: one CPU traversal per layout).
#include <gtest/gtest.h>

#ifdef LUCENT_HAVE_CUDA
#include <cstdlib>
#include <filesystem>
#include <random>
#include <vector>

#include "accel/triangle_accel.h"
#include "cuda/device/lucent_gpu/ray_order.cuh"
#include "cuda/embedded_sources.h"
#include "cuda/gpu_triangle_bvh.h"
#include "cuda/nvrtc_compiler.h"
#include "lucent/device/triangle_intersect.h"
#include "scene/obj_mesh.h"

namespace lucent {
namespace {

using cuda::GpuTriangleBvh;
using gpu::GpuHit;

std::string compile_log_or_skip(int sm, const std::vector<std::string>& extra,
                                cuda::CompileResult& out) {
    cuda::CompileRequest req;
    req.name = "lucent_bench_kernels.cu";
    req.source = "#include \"lucent_gpu/bench_kernels.cuh\"\n";
    for (const cuda::EmbeddedSource& s : cuda::embedded_sources())
        req.headers.emplace_back(std::string(s.name), std::string(s.text));
    req.options = {"--std=c++17", "--fmad=false"};
    req.options.insert(req.options.end(), extra.begin(), extra.end());
    req.sm = sm;
    out = cuda::compile_cubin(req);
    return out.log;
}

/// Triangles: random small ones, plus an axis-aligned grid of quads (shared edges, flat
/// boxes), the cases where a careless box test loses hits.
struct Mesh {
    std::vector<float3> positions;
    std::vector<uint3> indices;
};

Mesh test_mesh(unsigned seed, int random_count) {
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

std::vector<TestRay> test_rays(unsigned seed, int count) {
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

void expect_same_closest(const Brute& brute, const TestRay& r, bool gpu_hit, const GpuHit& g,
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

}  // namespace

TEST(jit, bench_kernels) {
    std::string why;
    if (cuda::nvrtc_version(&why).empty()) GTEST_SKIP() << why;
    setenv("LUCENT_CACHE_DIR", "off", 1);
    for (const char* persistent : {"-DLUCENT_BENCH_PERSISTENT=1", "-DLUCENT_BENCH_PERSISTENT=0"}) {
        cuda::CompileResult result;
        const std::string log = compile_log_or_skip(90, {persistent, "--ptxas-options=-v"}, result);
        EXPECT_FALSE(result.cubin.empty()) << persistent;
        EXPECT_FALSE(result.from_cache);
        // Registers and spills of each kernel, for the record.
        std::printf("%s: %zu-byte cubin, NVRTC log:\n%s\n", persistent, result.cubin.size(),
                    log.c_str());
        EXPECT_EQ(log.find("warning"), std::string::npos) << log;
    }
}

TEST(jit, gpu_bvh_layout_matches_brute_force) {
    const Mesh mesh = test_mesh(7, 1500);
    const Brute brute{mesh};
    const std::vector<TestRay> rays = test_rays(11, 3000);
    for (int leaf : {1, 4, 8}) {
        cuda::GpuBvhBuildOptions opt;
        opt.max_leaf_size = leaf;
        const GpuTriangleBvh bvh = cuda::build_gpu_triangle_bvh(mesh.positions, mesh.indices, opt);
        ASSERT_EQ(bvh.triangle_ids.size(), mesh.indices.size());
        ASSERT_EQ(bvh.triangles.size(), 3 * mesh.indices.size());
        const gpu::GpuTriangleBvhView view = bvh.host_view();
        for (size_t i = 0; i < rays.size(); ++i) {
            const TestRay& r = rays[i];
            SCOPED_TRACE("leaf size " + std::to_string(leaf));
            // Closest.
            GpuHit g{};
            const bool hit = gpu::gpu_bvh_closest(view, r.o, r.d, 0.0f, r.tmax, g);
            const GpuHit b = brute.closest(r.o, r.d, 0.0f, r.tmax, [](unsigned) { return true; });
            expect_same_closest(brute, r, hit, g, b, (int)i);
            // Any hit.
            EXPECT_EQ(gpu::gpu_bvh_occluded(view, r.o, r.d, 0.0f, r.tmax), b.t >= 0.0f) << i;
            // Filtered: ignore every third triangle; the closest of the others must come out.
            int offered = 0;
            GpuHit gf{};
            const bool fhit =
                gpu::gpu_bvh_filtered(view, r.o, r.d, 0.0f, r.tmax, gf, [&](const GpuHit& c) {
                    ++offered;
                    return c.prim % 3 == 0 ? gpu::kGpuIgnore : gpu::kGpuAccept;
                });
            const GpuHit bf =
                brute.closest(r.o, r.d, 0.0f, r.tmax, [](unsigned p) { return p % 3 != 0; });
            expect_same_closest(brute, r, fhit, gf, bf, (int)i);
            // Accept-and-stop ends at the first candidate.
            offered = 0;
            GpuHit gs{};
            const bool shit =
                gpu::gpu_bvh_filtered(view, r.o, r.d, 0.0f, r.tmax, gs, [&](const GpuHit&) {
                    ++offered;
                    return gpu::kGpuAcceptAndStop;
                });
            EXPECT_EQ(shit, b.t >= 0.0f) << i;
            EXPECT_LE(offered, 1) << i;
            if (shit) {
                EXPECT_EQ(brute.t_of(gs.prim, r.o, r.d), gs.t) << i;
            }
        }
    }
}

TEST(jit, gpu_bvh_small_meshes) {
    // No triangles: nothing is hit.
    const GpuTriangleBvh empty = cuda::build_gpu_triangle_bvh({}, {});
    GpuHit h{};
    EXPECT_FALSE(gpu::gpu_bvh_closest(empty.host_view(), make_float3(0, 0, -1),
                                      make_float3(0, 0, 1), 0.0f, kInfinity, h));
    EXPECT_EQ(empty.stats.node_count, 1u);
    // One triangle: the root's single leaf, beside an empty box.
    const std::vector<float3> one = {make_float3(-1, -1, 0), make_float3(1, -1, 0),
                                     make_float3(0, 1, 0)};
    const GpuTriangleBvh single = cuda::build_gpu_triangle_bvh(one, {});
    ASSERT_TRUE(gpu::gpu_bvh_closest(single.host_view(), make_float3(0, 0, -1),
                                     make_float3(0, 0, 1), 0.0f, kInfinity, h));
    EXPECT_EQ(h.t, 1.0f);
    EXPECT_EQ(h.prim, 0u);
    EXPECT_FALSE(gpu::gpu_bvh_occluded(single.host_view(), make_float3(0, 0, -1),
                                       make_float3(0, 0, 1), 0.0f, 0.5f));
    EXPECT_FALSE(gpu::gpu_bvh_closest(single.host_view(), make_float3(5, 0, -1),
                                      make_float3(0, 0, 1), 0.0f, kInfinity, h));
    // Leaf encoding round trip.
    for (unsigned first : {0u, 1u, 12345u, gpu::kGpuLeafFirstMask})
        for (unsigned count = 1; count <= 8; ++count) {
            const int leaf = gpu::gpu_make_leaf(first, count);
            EXPECT_LT(leaf, 0);
            EXPECT_EQ(gpu::gpu_leaf_first(leaf), first);
            EXPECT_EQ(gpu::gpu_leaf_count(leaf), count);
        }
}

TEST(jit, tiled_ray_order_is_a_permutation) {
    for (auto [w, h] :
         {std::pair{3840u, 2160u}, {1u, 1u}, {7u, 3u}, {13u, 9u}, {8u, 4u}, {33u, 17u}}) {
        std::vector<int> seen(w * h, 0);
        for (unsigned r = 0; r < w * h; ++r) {
            const unsigned p = gpu::gpu_tiled_pixel(r, w, h);
            ASSERT_LT(p, w * h) << w << "x" << h << " ray " << r;
            ++seen[p];
        }
        for (unsigned p = 0; p < w * h; ++p) ASSERT_EQ(seen[p], 1) << w << "x" << h;
    }
    // The first warp of a wide image covers an 8 x 4 tile.
    EXPECT_EQ(gpu::gpu_tiled_pixel(31, 3840, 2160), 3u * 3840 + 7);
}

TEST(jit, gpu_bvh_layout_matches_triangle_accel_on_sponza) {
    const std::string file = std::string(LUCENT_SCENES_DIR) + "/sponza.obj";
    if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " not found";
    const scene::ObjMesh mesh = scene::load_obj_mesh(file);
    const GpuTriangleBvh bvh = cuda::build_gpu_triangle_bvh(mesh.positions, mesh.indices);
    accel::TriangleAccel accel;
    accel.build(mesh.positions, mesh.indices);
    const Aabb box = accel.bounds();
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f), dir(-1.0f, 1.0f);
    const gpu::GpuTriangleBvhView view = bvh.host_view();
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        const float3 o = box.lo + (box.hi - box.lo) * make_float3(unit(rng), unit(rng), unit(rng));
        float3 d = make_float3(dir(rng), dir(rng), dir(rng));
        if (i % 9 == 0) d.y = 0.0f;
        if (dot(d, d) == 0.0f) continue;
        d = normalize(d);
        accel::TriangleHit c;
        GpuHit g{};
        const bool ch = accel.intersect(o, d, 0.0f, kInfinity, c);
        const bool gh = gpu::gpu_bvh_closest(view, o, d, 0.0f, kInfinity, g);
        ASSERT_EQ(gh, ch) << i;
        if (gh) {
            ++hits;
            EXPECT_EQ(g.t, c.t) << i;
        }
        const float tmax = 0.5f + 10.0f * unit(rng);
        EXPECT_EQ(gpu::gpu_bvh_occluded(view, o, d, 0.0f, tmax), accel.occluded(o, d, 0.0f, tmax))
            << i;
    }
    EXPECT_GT(hits, 10000);
}

}  // namespace lucent

#else

TEST(jit, bench_kernels) {
    GTEST_SKIP() << "built without the CUDA toolkit";
}

#endif

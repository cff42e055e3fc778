// The bench kernels compile with NVRTC, and the GPU triangle BVH layout, traversed on the
// CPU by the very code the GPU runs (triangle_bvh.cuh is host/device), finds the same
// hits as brute force and as TriangleAccel (every layout has a CPU traversal checked against brute
// force).
#include <gtest/gtest.h>

#ifdef LUCENT_HAVE_CUDA
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>
#include <vector>

#include "accel/triangle_accel.h"
#include "bench/gpu/bench_sources.h"
#include "cuda/accel/gpu_triangle_bvh.h"
#include "cuda/device/lucent_gpu/ray_order.cuh"
#include "cuda/jit/nvrtc_compiler.h"
#include "lucent/device/triangle_intersect.h"
#include "lucent/error.h"
#include "scene/obj_mesh.h"
#include "tests/triangle_test_meshes.h"

namespace lucent {
namespace {

using cuda::GpuTriangleBvh;
using gpu::GpuHit;
using namespace test_meshes;

std::string compile_log_or_skip(const std::vector<std::string>& extra, cuda::CompileResult& out) {
    std::vector<std::string> options = {"--std=c++17", "--fmad=false"};
    options.insert(options.end(), extra.begin(), extra.end());
    out = cuda::compile_cubin(cuda::bench_kernel_request(
        "lucent_bench_kernels.cu", "#include \"lucent_bench/trace_kernels.cuh\"\n", options, 90));
    return out.log;
}

}  // namespace

TEST(jit, bench_kernels) {
    std::string why;
    if (cuda::nvrtc_version(&why).empty()) GTEST_SKIP() << why;
    setenv("LUCENT_CACHE_DIR", "off", 1);
    for (const char* persistent : {"-DLUCENT_BENCH_PERSISTENT=1", "-DLUCENT_BENCH_PERSISTENT=0"}) {
        cuda::CompileResult result;
        const std::string log = compile_log_or_skip({persistent, "--ptxas-options=-v"}, result);
        EXPECT_FALSE(result.cubin.empty()) << persistent;
        EXPECT_FALSE(result.from_cache);
        // Registers and spills of each kernel, for the record.
        std::printf("%s: %zu-byte cubin, NVRTC log:\n%s\n", persistent, result.cubin.size(),
                    log.c_str());
        EXPECT_EQ(log.find("warning"), std::string::npos) << log;
        for (const char* kernel : {"lucent_bench_closest", "lucent_bench_any"})
            EXPECT_NE(log.find(kernel), std::string::npos) << kernel;
    }
}

TEST(jit, bench_tea_kernels) {
    // `bench tea --backend cuda`'s stream-ordered kernels compile without warnings, and the
    // TEA kernel's formula is the engine's programs' (checked on the GPU by the checksums).
    std::string why;
    if (cuda::nvrtc_version(&why).empty()) GTEST_SKIP() << why;
    setenv("LUCENT_CACHE_DIR", "off", 1);
    const cuda::CompileResult result = cuda::compile_cubin(cuda::bench_kernel_request(
        "lucent_bench_tea.cu", "#include \"lucent_bench/tea_kernels.cuh\"\n",
        {"--std=c++17", "--ptxas-options=-v"}, 90));
    EXPECT_FALSE(result.cubin.empty());
    EXPECT_EQ(result.log.find("warning"), std::string::npos) << result.log;
    for (const char* kernel : {"lucent_bench_tea", "lucent_bench_xor_fold"})
        EXPECT_NE(result.log.find(kernel), std::string::npos) << kernel;
}

TEST(jit, gpu_bvh_builder_kernels) {
    // The GPU builder's module (H-PLOC, radix sort, refit) compiles to sm_90 code, without
    // warnings, so `lucent bench build --backend cuda` can never silently stop compiling.
    std::string why;
    if (cuda::nvrtc_version(&why).empty()) GTEST_SKIP() << why;
    setenv("LUCENT_CACHE_DIR", "off", 1);
    const cuda::CompileResult result = cuda::compile_cubin(cuda::embedded_request(
        "lucent_bvh_build.cu",
        "#include \"lucent_gpu/bvh_build.cuh\"\n#include \"lucent_gpu/bvh_refit.cuh\"\n",
        {"--std=c++17", "--ptxas-options=-v"}, 90));
    EXPECT_FALSE(result.cubin.empty());
    std::printf("%zu-byte cubin, NVRTC log:\n%s\n", result.cubin.size(), result.log.c_str());
    EXPECT_EQ(result.log.find("warning"), std::string::npos) << result.log;
    for (const char* kernel :
         {"lucent_build_hploc", "lucent_build_emit", "lucent_radix_scatter", "lucent_refit_nodes"})
        EXPECT_NE(result.log.find(kernel), std::string::npos) << kernel;
}

TEST(jit, display_kernels) {
    // Display frames' module (sRGB encoding, the copy into an OpenGL texture's surface)
    // compiles to sm_90 code without warnings, with both kernels in it.
    std::string why;
    if (cuda::nvrtc_version(&why).empty()) GTEST_SKIP() << why;
    setenv("LUCENT_CACHE_DIR", "off", 1);
    const cuda::CompileResult result = cuda::compile_cubin(
        cuda::embedded_request("lucent_display.cu", "#include \"lucent_gpu/display.cuh\"\n",
                               {"--std=c++17", "--ptxas-options=-v"}, 90));
    EXPECT_FALSE(result.cubin.empty());
    EXPECT_EQ(result.log.find("warning"), std::string::npos) << result.log;
    for (const char* kernel : {"lucent_display_srgb8", "lucent_display_to_surface"})
        EXPECT_NE(result.log.find(kernel), std::string::npos) << kernel;
}

TEST(jit, gpu_bvh_layout_matches_brute_force) {
    const Mesh mesh = test_mesh(7, 1500);
    const Brute brute{mesh};
    const std::vector<TestRay> rays = test_rays(11, 3000);
    for (int leaf : {1, 4, 8})
        for (bool splits : {false, true}) {
            cuda::GpuBvhBuildOptions opt;
            opt.max_leaf_size = leaf;
            opt.spatial_splits = splits;
            const GpuTriangleBvh bvh =
                cuda::build_gpu_triangle_bvh(mesh.positions, mesh.indices, opt);
            // Every triangle in some leaf; with spatial splits in several, within the budget
            // (a quarter more references than triangles).
            std::vector<int> slots(mesh.indices.size(), 0);
            for (uint32_t id : bvh.triangle_ids) {
                ASSERT_LT(id, mesh.indices.size());
                ++slots[id];
            }
            for (size_t t = 0; t < slots.size(); ++t) ASSERT_GE(slots[t], 1) << t;
            if (splits) {
                EXPECT_GT(bvh.triangle_ids.size(), mesh.indices.size());
                EXPECT_LE(bvh.triangle_ids.size(), mesh.indices.size() * 5 / 4 + 1);
            } else {
                ASSERT_EQ(bvh.triangle_ids.size(), mesh.indices.size());
            }
            ASSERT_EQ(bvh.triangles.size(), 3 * bvh.triangle_ids.size());
            const gpu::GpuTriangleBvhView view = bvh.host_view();
            for (size_t i = 0; i < rays.size(); ++i) {
                const TestRay& r = rays[i];
                SCOPED_TRACE("leaf size " + std::to_string(leaf) +
                             (splits ? ", spatial splits" : ""));
                // Closest.
                GpuHit g{};
                const bool hit = gpu::gpu_bvh_closest(view, r.o, r.d, 0.0f, r.tmax, g);
                const GpuHit b =
                    brute.closest(r.o, r.d, 0.0f, r.tmax, [](unsigned) { return true; });
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

TEST(jit, gpu_bvh_layout_gives_back_its_input_triangles) {
    // What a tree upgrade builds from (TreeUpgrader): the GPU tree's triangles, put back in
    // input order, build the same tree with spatial splits as the input mesh does.
    // The floor overlaps the clutter: spatial splits happen.
    const Mesh mesh = floor_and_clutter(5, 600);
    cuda::GpuBvhBuildOptions no_splits;
    no_splits.spatial_splits = false;
    const GpuTriangleBvh gpu_like =
        cuda::build_gpu_triangle_bvh(mesh.positions, mesh.indices, no_splits);
    const std::vector<float3> back =
        cuda::layout_input_triangles(gpu_like.triangles, gpu_like.triangle_ids);
    ASSERT_EQ(back.size(), 3 * mesh.indices.size());
    for (size_t t = 0; t < mesh.indices.size(); ++t) {
        const uint3 i = mesh.indices[t];
        for (int v = 0; v < 3; ++v) {
            const float3 expected = mesh.positions[v == 0 ? i.x : v == 1 ? i.y : i.z];
            ASSERT_EQ(back[3 * t + v].x, expected.x) << "triangle " << t << " vertex " << v;
            ASSERT_EQ(back[3 * t + v].y, expected.y) << "triangle " << t << " vertex " << v;
            ASSERT_EQ(back[3 * t + v].z, expected.z) << "triangle " << t << " vertex " << v;
        }
    }
    const GpuTriangleBvh upgraded = cuda::build_gpu_triangle_bvh(back, {});
    const GpuTriangleBvh direct = cuda::build_gpu_triangle_bvh(mesh.positions, mesh.indices);
    EXPECT_GT(direct.triangle_ids.size(), mesh.indices.size()) << "no spatial split happened";
    EXPECT_EQ(upgraded.triangle_ids, direct.triangle_ids);
    ASSERT_EQ(upgraded.nodes.size(), direct.nodes.size());
    for (size_t n = 0; n < direct.nodes.size(); ++n) {
        // Bit for bit: child references are integers in float bits (some are NaN patterns).
        ASSERT_EQ(std::memcmp(&upgraded.nodes[n], &direct.nodes[n], sizeof(float4)), 0)
            << "node float4 " << n;
    }
    // A layout with spatial splits holds some triangles twice: it cannot give its input back.
    try {
        cuda::layout_input_triangles(direct.triangles, direct.triangle_ids);
        FAIL() << "a layout with spatial splits gave its input back";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("already in another slot"), std::string::npos)
            << e.what();
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
    // Both with spatial splits (their default): Sponza's long triangles get split.
    const GpuTriangleBvh bvh = cuda::build_gpu_triangle_bvh(mesh.positions, mesh.indices);
    EXPECT_GT(bvh.triangle_ids.size(), mesh.indices.size());
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

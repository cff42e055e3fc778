// The compressed wide GPU layout (cwbvh.cuh), traversed on the CPU by the code a kernel
// runs: the same hits as brute force and as the binary GPU layout, boxes that hold what
// they should, exact grids, and a traversal that compiles with NVRTC.
#include <gtest/gtest.h>

#ifdef LUCENT_HAVE_CUDA
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "bench/gpu/bench_sources.h"
#include "bench/gpu/gpu_cwbvh.h"
#include "cuda/jit/nvrtc_compiler.h"
#include "lucent/error.h"
#include "scene/obj_mesh.h"
#include "tests/triangle_test_meshes.h"

namespace lucent {
namespace {

using cuda::GpuCwbvh;
using gpu::GpuHit;
using namespace test_meshes;

/// Every ray: closest, any and filtered hits equal brute force's.
void expect_brute_force(const Mesh& mesh, const GpuCwbvh& bvh, const std::vector<TestRay>& rays) {
    const Brute brute{mesh};
    const gpu::GpuCwbvhView view = bvh.host_view();
    for (size_t i = 0; i < rays.size(); ++i) {
        const TestRay& r = rays[i];
        GpuHit g{};
        const bool hit = gpu::gpu_cwbvh_closest(view, r.o, r.d, 0.0f, r.tmax, g);
        const GpuHit b = brute.closest(r.o, r.d, 0.0f, r.tmax, [](unsigned) { return true; });
        expect_same_closest(brute, r, hit, g, b, (int)i);
        EXPECT_EQ(gpu::gpu_cwbvh_occluded(view, r.o, r.d, 0.0f, r.tmax), b.t >= 0.0f) << i;
        GpuHit gf{};
        const bool fhit = gpu::gpu_cwbvh_filtered(
            view, r.o, r.d, 0.0f, r.tmax, gf,
            [](const GpuHit& c) { return c.prim % 3 == 0 ? gpu::kGpuIgnore : gpu::kGpuAccept; });
        const GpuHit bf =
            brute.closest(r.o, r.d, 0.0f, r.tmax, [](unsigned p) { return p % 3 != 0; });
        expect_same_closest(brute, r, fhit, gf, bf, (int)i);
    }
}

/// Walks the layout: every leaf's triangles lie inside the leaf's decoded box, every child
/// node's decoded box holds its own children's, and each triangle appears exactly once.
void expect_boxes_hold(const GpuCwbvh& bvh, size_t triangle_count) {
    std::vector<int> seen(triangle_count, 0);
    std::vector<unsigned> todo = {0};
    auto inside = [](float3 p, float3 lo, float3 hi) {
        return p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x <= hi.x && p.y <= hi.y &&
               p.z <= hi.z;
    };
    while (!todo.empty()) {
        const unsigned index = todo.back();
        todo.pop_back();
        ASSERT_LT(index, bvh.stats.node_count);
        const auto node = gpu::GpuCwbvhNode::load(bvh.nodes.data(), index);
        for (int i = 0; i < gpu::kCwbvhArity; ++i) {
            if (node.slot_meta(i) == 0u) continue;
            float3 lo, hi;
            node.child_box(i, lo, hi);
            const int ref = node.child_ref(i);
            if (ref >= 0) {
                const auto child = gpu::GpuCwbvhNode::load(bvh.nodes.data(), (unsigned)ref);
                for (int j = 0; j < gpu::kCwbvhArity; ++j) {
                    if (child.slot_meta(j) == 0u) continue;
                    float3 clo, chi;
                    child.child_box(j, clo, chi);
                    EXPECT_TRUE(inside(clo, lo, hi) && inside(chi, lo, hi))
                        << "node " << ref << " slot " << j;
                }
                todo.push_back((unsigned)ref);
                continue;
            }
            const unsigned first = gpu::gpu_leaf_first(ref), count = gpu::gpu_leaf_count(ref);
            ASSERT_LE(count, (unsigned)gpu::kCwbvhMaxLeafSize);
            for (unsigned t = first; t < first + count; ++t) {
                ASSERT_LT(t, bvh.triangle_ids.size());
                ++seen[bvh.triangle_ids[t]];
                for (int v = 0; v < 3; ++v) {
                    const float4 p = bvh.triangles[3 * t + v];
                    EXPECT_TRUE(inside(make_float3(p.x, p.y, p.z), lo, hi))
                        << "triangle " << bvh.triangle_ids[t];
                }
            }
        }
    }
    for (size_t t = 0; t < triangle_count; ++t) EXPECT_EQ(seen[t], 1) << "triangle " << t;
}

}  // namespace

TEST(GpuCwbvh, GridsAreExactAndReachAcross) {
    for (float lo : {0.0f, -1.0f, 3.75f, 1e-30f, -2e5f, 123456.7f, -3e30f})
        for (float extent : {0.0f, 1e-7f, 0.01f, 1.0f, 7.5f, 1000.0f, 3e6f}) {
            const float hi = lo + extent;
            const cuda::CwbvhAxisGrid g = cuda::cwbvh_axis_grid(lo, hi);
            const float step = gpu::cwbvh_step(g.biased_exponent);
            EXPECT_LE(g.origin, lo);
            EXPECT_GE(std::fma(255.0f, step, g.origin), hi) << lo << " + " << extent;
            // Every plane origin + q * step is a float: one FMA and the long sum agree.
            for (int q = 0; q <= 255; ++q)
                ASSERT_EQ(double(std::fma(float(q), step, g.origin)),
                          double(g.origin) + double(q) * double(step))
                    << lo << " + " << extent << ", q " << q;
            // No coarser than the extent (255 steps) or the coordinates' own precision
            // (about 2 ulp of the larger end) ask for, within two doublings.
            const double magnitude = std::max(std::fabs(double(lo)), std::fabs(double(hi)));
            EXPECT_LE(double(step),
                      4.0 * std::max({double(extent) / 255.0, magnitude * 0x1p-23, 0x1p-126}))
                << lo << " + " << extent;
        }
    EXPECT_THROW(cuda::cwbvh_axis_grid(1.0f, 0.0f), Error);
    EXPECT_THROW(cuda::cwbvh_axis_grid(0.0f, INFINITY), Error);
}

TEST(GpuCwbvh, EqualsBruteForceForEveryLeafSize) {
    const Mesh mesh = test_mesh(7, 1500);
    const std::vector<TestRay> rays = test_rays(11, 3000);
    for (int leaf : {1, 2, 3}) {
        SCOPED_TRACE("leaf size " + std::to_string(leaf));
        cuda::GpuBvhBuildOptions options;
        options.max_leaf_size = leaf;
        const GpuCwbvh bvh = cuda::build_gpu_cwbvh(mesh.positions, mesh.indices, options);
        ASSERT_EQ(bvh.triangle_ids.size(), mesh.indices.size());
        EXPECT_LT(bvh.stats.node_count, mesh.indices.size() / 2);
        expect_boxes_hold(bvh, mesh.indices.size());
        expect_brute_force(mesh, bvh, rays);
    }
}

TEST(GpuCwbvh, FarFromTheOriginEqualsBruteForce) {
    // Grids far from the origin are coarser (origin / step must stay within the floats'
    // integers); the boxes must still hold and no hit be lost.
    Mesh mesh = test_mesh(21, 1200);
    std::vector<TestRay> rays = test_rays(5, 2000);
    const float3 offset = make_float3(2.0e5f, -1.0e6f, 3.0e4f);
    for (float3& p : mesh.positions) p = p + offset;
    for (TestRay& r : rays) r.o = r.o + offset;
    const GpuCwbvh bvh = cuda::build_gpu_cwbvh(mesh.positions, mesh.indices);
    expect_boxes_hold(bvh, mesh.indices.size());
    expect_brute_force(mesh, bvh, rays);
}

TEST(GpuCwbvh, SmallAndEmptyMeshesAndBadInput) {
    GpuHit h{};
    const GpuCwbvh empty = cuda::build_gpu_cwbvh({}, {});
    EXPECT_EQ(empty.stats.node_count, 1u);
    EXPECT_FALSE(gpu::gpu_cwbvh_closest(empty.host_view(), make_float3(0, 0, -1),
                                        make_float3(0, 0, 1), 0.0f, kInfinity, h));
    EXPECT_FALSE(gpu::gpu_cwbvh_occluded(empty.host_view(), make_float3(0, 0, -1),
                                         make_float3(0, 0, 1), 0.0f, kInfinity));
    const std::vector<float3> one = {make_float3(-1, -1, 0), make_float3(1, -1, 0),
                                     make_float3(0, 1, 0)};
    const GpuCwbvh single = cuda::build_gpu_cwbvh(one, {});
    ASSERT_TRUE(gpu::gpu_cwbvh_closest(single.host_view(), make_float3(0, 0, -1),
                                       make_float3(0, 0, 1), 0.0f, kInfinity, h));
    EXPECT_EQ(h.t, 1.0f);
    EXPECT_EQ(h.prim, 0u);
    EXPECT_FALSE(gpu::gpu_cwbvh_occluded(single.host_view(), make_float3(0, 0, -1),
                                         make_float3(0, 0, 1), 0.0f, 0.5f));
    // Unindexed input of a few triangles: one node, its slots leaves.
    const Mesh small = test_mesh(3, 9);
    std::vector<float3> soup;
    for (const uint3& t : small.indices)
        soup.insert(soup.end(), {small.positions[t.x], small.positions[t.y], small.positions[t.z]});
    const GpuCwbvh unindexed = cuda::build_gpu_cwbvh(soup, {});
    EXPECT_EQ(unindexed.triangle_ids.size(), small.indices.size());
    expect_brute_force(small, unindexed, test_rays(4, 500));
    // Bad input names the layout and the triangle.
    const std::vector<uint3> out_of_range = {make_uint3(0, 1, 7)};
    try {
        cuda::build_gpu_cwbvh(one, out_of_range);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("GPU compressed wide BVH: triangle 0"),
                  std::string::npos)
            << e.what();
    }
    cuda::GpuBvhBuildOptions wide_leaves;
    wide_leaves.max_leaf_size = 4;  // the unary count holds three
    EXPECT_THROW(cuda::build_gpu_cwbvh(one, {}, wide_leaves), Error);
}

TEST(GpuCwbvh, MetaBytesGiveThePapersHitMaskBits) {
    const Mesh mesh = test_mesh(2, 800);
    const GpuCwbvh bvh = cuda::build_gpu_cwbvh(mesh.positions, mesh.indices);
    for (unsigned index = 0; index < bvh.stats.node_count; ++index) {
        const auto node = gpu::GpuCwbvhNode::load(bvh.nodes.data(), index);
        unsigned triangle_bits = 0;
        for (int i = 0; i < gpu::kCwbvhArity; ++i) {
            const unsigned meta = node.slot_meta(i);
            if (meta == 0u) continue;
            const unsigned bits = (meta >> 5) << (meta & 31);
            if (node.inner & (1u << i)) {
                EXPECT_EQ(bits, 1u << (gpu::kCwbvhInnerBit + i)) << index << " " << i;
            } else {
                const int leaf = node.child_ref(i);
                const unsigned first = gpu::gpu_leaf_first(leaf) - node.triangle_base;
                const unsigned count = gpu::gpu_leaf_count(leaf);
                EXPECT_EQ(bits, ((1u << count) - 1u) << first) << index << " " << i;
                EXPECT_EQ(triangle_bits & bits, 0u) << "leaves overlap";
                triangle_bits |= bits;
            }
        }
        EXPECT_LT(triangle_bits, 1u << gpu::kCwbvhMaxNodeTriangles);
    }
}

TEST(GpuCwbvh, SlotsGiveAFrontToBackOrderByOctant) {
    // Among the hit children of a node, the first in the order slot ^ octant should be the
    // nearest one far more often than the first in memory order is.
    const Mesh mesh = test_mesh(13, 4000);
    const GpuCwbvh bvh = cuda::build_gpu_cwbvh(mesh.positions, mesh.indices);
    int nodes = 0, octant_first = 0, memory_first = 0;
    for (const TestRay& r : test_rays(17, 2000)) {
        gpu::GpuCwbvhRay ray;
        ray.start(r.o, r.d, 0.0f, r.tmax);
        const unsigned octant = (r.d.x < 0.0f) | (r.d.y < 0.0f) << 1 | (r.d.z < 0.0f) << 2;
        std::vector<unsigned> todo = {0};
        while (!todo.empty()) {
            const auto node = gpu::GpuCwbvhNode::load(bvh.nodes.data(), todo.back());
            todo.pop_back();
            float best_t = kInfinity;
            int nearest = -1, by_octant = -1, by_memory = -1, hits = 0;
            for (int i = 0; i < gpu::kCwbvhArity; ++i) {
                if (node.slot_meta(i) == 0u) continue;
                float3 lo, hi;
                node.child_box(i, lo, hi);
                float t_near, t_far;
                gpu::GpuBvhTraversal::slab(lo.x, hi.x, lo.y, hi.y, lo.z, hi.z, ray, t_near, t_far);
                if (!(t_near <= t_far)) continue;
                ++hits;
                if (t_near < best_t) best_t = t_near, nearest = i;
                if (by_octant < 0 || (unsigned(i) ^ octant) < (unsigned(by_octant) ^ octant))
                    by_octant = i;
                if (by_memory < 0) by_memory = i;
                if (node.child_ref(i) >= 0) todo.push_back((unsigned)node.child_ref(i));
            }
            if (hits < 2) continue;
            ++nodes;
            octant_first += by_octant == nearest;
            memory_first += by_memory == nearest;
        }
    }
    std::printf(
        "%d nodes with two or more children hit: nearest first %.1f %% by octant, "
        "%.1f %% in memory order\n",
        nodes, 100.0 * octant_first / nodes, 100.0 * memory_first / nodes);
    ASSERT_GT(nodes, 1000);
    EXPECT_GT(octant_first, memory_first + nodes / 10);
}

TEST(GpuCwbvh, SponzaHitsEqualTheBinaryLayout) {
    const std::filesystem::path path = "../shared/scenes/sponza.obj";
    std::filesystem::path found;
    for (const char* prefix : {"", "../", "../../", "../../../"})
        if (std::filesystem::exists(prefix / path)) found = prefix / path;
    if (found.empty()) GTEST_SKIP() << "../shared/scenes/sponza.obj not found";
    const scene::ObjMesh mesh = scene::load_obj_mesh(found.string());
    const GpuCwbvh wide = cuda::build_gpu_cwbvh(mesh.positions, mesh.indices);
    const cuda::GpuTriangleBvh binary = cuda::build_gpu_triangle_bvh(mesh.positions, mesh.indices);
    std::printf("sponza: %zu wide nodes (%zu bytes), %zu binary nodes (%zu bytes)\n",
                wide.stats.node_count, wide.nodes.size() * sizeof(float4), binary.stats.node_count,
                binary.nodes.size() * sizeof(float4));
    EXPECT_LT(wide.nodes.size() * sizeof(float4), binary.nodes.size() * sizeof(float4));
    // Rays through the scene's box in every direction.
    const Aabb box = [&] {
        Aabb b{make_float3(kInfinity), make_float3(-kInfinity)};
        for (const float3& p : mesh.positions) b.lo = fminf(b.lo, p), b.hi = fmaxf(b.hi, p);
        return b;
    }();
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    int hits = 0;
    for (int i = 0; i < 4000; ++i) {
        const float3 o = box.lo + (box.hi - box.lo) * make_float3(uni(rng), uni(rng), uni(rng));
        const float3 d = normalize(make_float3(uni(rng) - 0.5f, uni(rng) - 0.5f, uni(rng) - 0.5f));
        GpuHit a{}, b{};
        const bool ha = gpu::gpu_cwbvh_closest(wide.host_view(), o, d, 0.0f, kInfinity, a);
        const bool hb = gpu::gpu_bvh_closest(binary.host_view(), o, d, 0.0f, kInfinity, b);
        ASSERT_EQ(ha, hb) << i;
        if (!ha) continue;
        ++hits;
        EXPECT_EQ(a.t, b.t) << i;
        EXPECT_EQ(gpu::gpu_cwbvh_occluded(wide.host_view(), o, d, 0.0f, kInfinity), true) << i;
    }
    EXPECT_GT(hits, 3000);
}

TEST(jit, gpu_cwbvh_traversal) {
    // The traversal compiles to sm_90 code without warnings, so a kernel over the layout can
    // be written on it.
    std::string why;
    if (cuda::nvrtc_version(&why).empty()) GTEST_SKIP() << why;
    setenv("LUCENT_CACHE_DIR", "off", 1);
    const char* source = R"(#include "lucent_bench/cwbvh.cuh"
extern "C" __global__ void lucent_cwbvh_probe(lucent::gpu::GpuCwbvhView bvh, const float4* rays,
                                              float* t, int count) {
    const int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= count) return;
    const float4 o = rays[2 * i], d = rays[2 * i + 1];
    lucent::gpu::GpuHit hit;
    const bool found = lucent::gpu::gpu_cwbvh_closest(bvh, make_float3(o.x, o.y, o.z),
                                                      make_float3(d.x, d.y, d.z), 0.0f, o.w, hit);
    const bool blocked = lucent::gpu::gpu_cwbvh_occluded(bvh, make_float3(o.x, o.y, o.z),
                                                         make_float3(d.x, d.y, d.z), 0.0f, o.w);
    t[i] = found ? hit.t : (blocked ? -2.0f : -1.0f);
}
)";
    const cuda::CompileResult result = cuda::compile_cubin(cuda::bench_kernel_request(
        "lucent_cwbvh_probe.cu", source, {"--std=c++17", "--ptxas-options=-v"}, 90));
    EXPECT_FALSE(result.cubin.empty()) << result.log;
    EXPECT_EQ(result.log.find("warning"), std::string::npos) << result.log;
    std::printf("NVRTC log:\n%s\n", result.log.c_str());
}

}  // namespace lucent

#endif  // LUCENT_HAVE_CUDA

// `lucent bench rays --programs` (bench/rays/programs_bench.h): the ray sets traced by the
// rays_programs.h module through a Context on the CPU give the checksums of the bare
// traversal (TriangleAccel) on the same rays, and the passes paired with the launches
// give the ratios.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "accel/triangle_accel.h"
#include "bench/common/bench_camera.h"
#include "bench/rays/programs_bench.h"
#include "bench/rays/ray_sets.h"

namespace {

using namespace lucent;
using namespace lucent::bench;

/// The checksums of TriangleAccel's closest and any-hit queries on the BENCH.md ray sets.
RayChecksums kernel_checksums(const scene::ObjMesh& mesh, const RaySet& primary, float3 light) {
    accel::TriangleAccel accel;
    accel.build(mesh.positions, mesh.indices, {});
    RayChecksums c;
    std::vector<float> t(primary.size());
    std::vector<uint32_t> prim(primary.size());
    for (size_t i = 0; i < primary.size(); ++i) {
        accel::TriangleHit hit;
        const bool h = accel.intersect(primary.origin[i], primary.direction[i], 0.0f,
                                       primary.tmax[i], hit);
        t[i] = h ? hit.t : -1.0f;
        prim[i] = h ? hit.prim : 0;
        if (h) ++c.primary_hits, c.primary_sum_t += hit.t;
    }
    RaySet shadow, diffuse;
    secondary_rays(primary, t.data(), prim.data(), mesh, light, shadow, diffuse);
    c.shadow_rays = shadow.size();
    for (size_t i = 0; i < shadow.size(); ++i)
        c.occluded += accel.occluded(shadow.origin[i], shadow.direction[i], 0.0f, shadow.tmax[i]);
    c.diffuse_rays = diffuse.size();
    for (size_t i = 0; i < diffuse.size(); ++i) {
        accel::TriangleHit hit;
        if (accel.intersect(diffuse.origin[i], diffuse.direction[i], 0.0f, diffuse.tmax[i], hit))
            ++c.diffuse_hits, c.diffuse_sum_t += hit.t;
    }
    return c;
}

/// A scene that needs no files (CI has no shared scenes): a floor, a back wall and a quad
/// floating above the floor, so that the camera's rays both hit and miss and the light
/// above is blocked for part of the floor.
scene::ObjMesh open_box_with_occluder() {
    scene::ObjMesh mesh;
    auto quad = [&](float3 a, float3 b, float3 c, float3 d) {
        const unsigned base = (unsigned)mesh.positions.size();
        for (float3 v : {a, b, c, d}) mesh.positions.push_back(v);
        mesh.indices.push_back(make_uint3(base, base + 1, base + 2));
        mesh.indices.push_back(make_uint3(base, base + 2, base + 3));
    };
    quad(make_float3(-1, 0, -1), make_float3(-1, 0, 1), make_float3(1, 0, 1), make_float3(1, 0, -1));
    quad(make_float3(-1, 0, -1), make_float3(1, 0, -1), make_float3(1, 1, -1), make_float3(-1, 1, -1));
    quad(make_float3(-0.3f, 0.6f, -0.3f), make_float3(0.3f, 0.6f, -0.3f),
         make_float3(0.3f, 0.6f, 0.3f), make_float3(-0.3f, 0.6f, 0.3f));
    return mesh;
}

/// A camera looking into that box, its light above the floating quad.
Camera box_camera() {
    return Camera{make_float3(0, 0.8f, 3), make_float3(0, 0.4f, 0), make_float3(0, 1, 0), 60.0f,
                  make_float3(0.1f, 1.5f, 0.1f)};
}

TEST(BenchPrograms, CpuProgramsGiveTheKernelsChecksums) {
    const scene::ObjMesh mesh = open_box_with_occluder();
    const Camera cam = box_camera();
    const RaySet primary = primary_rays(cam, 96, 72);
    const RayChecksums kernels = kernel_checksums(mesh, primary, cam.light);
    // Every kind of answer occurs: hits and misses, blocked and free shadow rays.
    ASSERT_GT(kernels.primary_hits, 0u);
    ASSERT_LT(kernels.primary_hits, primary.size());
    ASSERT_GT(kernels.occluded, 0u);
    ASSERT_LT(kernels.occluded, kernels.shadow_rays);
    ASSERT_GT(kernels.diffuse_hits, 0u);

    ProgramsInput in;
    in.mesh = &mesh;
    in.primary = &primary;
    in.light = cam.light;
    in.backend = BackendKind::kCpu;
    in.threads = 2;
    in.repeat = 1;
    // Each ray waited for (trace(), occluded()), then deferred (the *_deferred entries).
    for (const bool deferred : {false, true}) {
        SCOPED_TRACE(deferred ? "deferred" : "waited for");
        in.deferred = deferred;
        const ProgramsResult p = run_programs(in);
        EXPECT_EQ(checksum_differences(p, kernels, "programs", "kernels"), "");
        EXPECT_EQ(p.primary_hits, kernels.primary_hits);
        EXPECT_EQ(p.shadow_rays, kernels.shadow_rays);
        EXPECT_EQ(p.occluded, kernels.occluded);
        EXPECT_EQ(p.diffuse_rays, kernels.diffuse_rays);
        EXPECT_EQ(p.diffuse_hits, kernels.diffuse_hits);
        EXPECT_GT(p.primary.median, 0.0);
        EXPECT_GT(p.shadow.median, 0.0);
        EXPECT_GT(p.diffuse.median, 0.0);
        EXPECT_EQ(p.timing, "launch");
    }
}

TEST(BenchPrograms, PairedPassesRunBesideEachLaunchAndGiveTheirRatios) {
    const scene::ObjMesh mesh = open_box_with_occluder();
    const Camera cam = box_camera();
    const RaySet primary = primary_rays(cam, 96, 72);
    ProgramsInput in;
    in.mesh = &mesh;
    in.primary = &primary;
    in.light = cam.light;
    in.threads = 2;
    in.repeat = 3;
    // Two engines whose passes take 1 s and 2 s: each ratio is then the launch's rate in
    // rays per second over the set's size (times 2), a median of odd count like the rate's.
    std::map<RayKind, std::vector<size_t>> calls;
    in.paired_passes = [&](RayKind kind, const RaySet& rays) {
        calls[kind].push_back(rays.size());
        return std::vector<double>{1.0, 2.0};
    };
    const ProgramsResult p = run_programs(in);
    // One warm-up pass and one pass per timed launch, over the rays the launch traces.
    EXPECT_EQ(calls[RayKind::kPrimary], std::vector<size_t>(4, primary.size()));
    EXPECT_EQ(calls[RayKind::kShadow], std::vector<size_t>(4, p.shadow_rays));
    EXPECT_EQ(calls[RayKind::kDiffuse], std::vector<size_t>(4, p.diffuse_rays));
    ASSERT_EQ(p.paired.size(), 2u);
    EXPECT_NEAR(p.paired[0].primary, p.primary.median * 1e6 / primary.size(),
                1e-9 * p.paired[0].primary);
    EXPECT_NEAR(p.paired[0].shadow, p.shadow.median * 1e6 / p.shadow_rays,
                1e-9 * p.paired[0].shadow);
    EXPECT_NEAR(p.paired[0].diffuse, p.diffuse.median * 1e6 / p.diffuse_rays,
                1e-9 * p.paired[0].diffuse);
    EXPECT_DOUBLE_EQ(p.paired[1].primary, 2 * p.paired[0].primary);
    EXPECT_DOUBLE_EQ(p.paired[1].diffuse, 2 * p.paired[0].diffuse);
}

}  // namespace

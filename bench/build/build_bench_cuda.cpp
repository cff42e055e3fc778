// `lucent bench build --backend cuda`: the GPU builder's time (its kernels, on triangles
// already in device memory) and refit, the host binned-SAH build with its conversion and
// upload, and both trees on the same rays with every hit compared.
#include "bench/build/build_bench_cuda.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/common/rate.h"
#include "bench/common/report.h"
#include "bench/gpu/ray_bench.h"
#include "cuda/accel/gpu_bvh_builder.h"
#include "cuda/accel/gpu_triangle_bvh.h"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {

using bench::Json;
using bench::rounded;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/// One tree's Mrays/s on the three ray sets.
struct TreeRates {
    Rate primary, shadow, diffuse;
};

/// What `lucent bench build --backend cuda` measured.
struct CudaBuildResult {
    const CudaBuildInput* in = nullptr;
    std::string device;
    size_t triangles = 0;
    GpuBvhStats hploc;  // the GPU builder's last build
    Rate gpu_ms;        // its builds
    double refit_ms = 0, mesh_upload_ms = 0;
    double host_ms = 0;  // the host build + conversion + upload, median
    GpuBvhStats host;
    // Both trees on the same rays (none without a viewpoint).
    size_t ray_count = 0, differ_primary = 0, differ_shadow = 0, differ_diffuse = 0;
    TreeRates rates_hploc, rates_sah;
};

Json to_json(const CudaBuildResult& r) {
    const CudaBuildInput& in = *r.in;
    const double ms = r.gpu_ms.median;
    Json j{{"scene", in.scene},
           {"backend", "cuda"},
           {"device", r.device},
           {"triangles", r.triangles},
           {"builder", r.hploc.builder},
           {"build_ms", rounded(ms, 4)},
           {"min_ms", rounded(r.gpu_ms.min, 4)},
           {"max_ms", rounded(r.gpu_ms.max, 4)},
           {"mtris_per_s", rounded(r.triangles / ms * 1e-3, 3)},
           {"sah_cost", rounded(r.hploc.sah_cost, 4)},
           {"nodes", r.hploc.node_count},
           {"depth", r.hploc.depth},
           {"refit_ms", rounded(r.refit_ms, 4)},
           {"mesh_upload_ms", rounded(r.mesh_upload_ms, 3)},
           {"host_sah_ms", rounded(r.host_ms, 3)},
           {"host_sah_cost", rounded(r.host.sah_cost, 4)}};
    if (r.ray_count) {
        auto mrays = [](const TreeRates& t) {
            return Json{{"primary", rounded(t.primary.median, 2)},
                        {"shadow", rounded(t.shadow.median, 2)},
                        {"diffuse", rounded(t.diffuse.median, 2)}};
        };
        j["width"] = in.width;
        j["height"] = in.height;
        j["mrays"] = mrays(r.rates_hploc);
        j["host_sah_mrays"] = mrays(r.rates_sah);
        j["rays_differing"] = r.differ_primary + r.differ_shadow + r.differ_diffuse;
    }
    return j;
}

void print_text(const CudaBuildResult& r) {
    const CudaBuildInput& in = *r.in;
    const double ms = r.gpu_ms.median;
    std::printf("scene %s: %zu triangles, GPU %s, median of %d builds\n", in.scene.c_str(),
                r.triangles, r.device.c_str(), in.repeat);
    std::printf(
        "GPU build (%s) %.3f ms (min %.3f, max %.3f) %.1f Mtris/s sah=%.3f nodes=%zu depth=%u "
        "(GPU time of its kernels; the mesh upload %.2f ms is apart)\n",
        r.hploc.builder, ms, r.gpu_ms.min, r.gpu_ms.max, r.triangles / ms * 1e-3, r.hploc.sah_cost,
        r.hploc.node_count, r.hploc.depth, r.mesh_upload_ms);
    std::printf("GPU refit %.3f ms\n", r.refit_ms);
    std::printf(
        "host build (binned SAH + layout + upload) %.2f ms %.2f Mtris/s sah=%.3f nodes=%zu "
        "depth=%u\n",
        r.host_ms, r.triangles / r.host_ms * 1e-3, r.host.sah_cost, r.host.node_count,
        r.host.depth);
    if (!r.ray_count) {
        std::printf("no rays traced: no viewpoint for this scene (cameras.txt)\n");
        return;
    }
    const TreeRates &a = r.rates_hploc, &b = r.rates_sah;
    std::printf("rays %ux%u (BENCH.md sets), Mrays/s, GPU-built tree / host SAH tree:\n", in.width,
                in.height);
    std::printf("primary %.2f / %.2f (%.3fx)\n", a.primary.median, b.primary.median,
                bench::median_ratio(a.primary, b.primary));
    std::printf("shadow %.2f / %.2f (%.3fx)\n", a.shadow.median, b.shadow.median,
                bench::median_ratio(a.shadow, b.shadow));
    std::printf("diffuse %.2f / %.2f (%.3fx)\n", a.diffuse.median, b.diffuse.median,
                bench::median_ratio(a.diffuse, b.diffuse));
    std::printf(
        "hits: %zu of %zu rays differ between the trees (primary %zu, shadow %zu, "
        "diffuse %zu)\n",
        r.differ_primary + r.differ_shadow + r.differ_diffuse, r.ray_count, r.differ_primary,
        r.differ_shadow, r.differ_diffuse);
}

/// One tree on the three ray sets: its rates, and what each ray found.
struct TreeRun {
    TreeRates rates;
    std::vector<uint2> primary_hits, diffuse_hits;
    std::vector<unsigned char> occluded;
};

TreeRun time_tree(RayBench& bench, const gpu::GpuTriangleBvhView& view) {
    TreeRun run;
    run.rates.primary = bench.time_primary(view);
    run.rates.shadow = bench.time_shadow(view);
    run.rates.diffuse = bench.time_diffuse(view);
    run.primary_hits.resize(bench.n), run.occluded.resize(bench.m);
    run.diffuse_hits.resize(bench.m);
    bench.primary_hits.download(run.primary_hits.data(), sizeof(uint2) * run.primary_hits.size());
    bench.occluded.download(run.occluded.data(), run.occluded.size());
    bench.diffuse_hits.download(run.diffuse_hits.data(), sizeof(uint2) * run.diffuse_hits.size());
    return run;
}

/// Both trees on the same rays (BENCH.md's sets, from the host tree's primary hits); every
/// hit compared.
void compare_trees(const DriverApi& api, const ContextScope& ctx, const CudaBuildInput& in,
                   const GpuTriangleBvh& sah_bvh, const GpuTriangleBvhDevice& sah,
                   const GpuTriangleBvhDevice& hploc, CudaBuildResult& result) {
    RayBench bench(api, ctx, RaySetsSpec{*in.camera, in.width, in.height, in.repeat});
    const DeviceBuffer by_prim = triangles_by_prim(sah_bvh);
    bench.make_rays(sah.view(), by_prim);
    const TreeRun a = time_tree(bench, sah.view());
    const TreeRun b = time_tree(bench, hploc.view());
    result.rates_sah = a.rates;
    result.rates_hploc = b.rates;
    for (size_t i = 0; i < a.primary_hits.size(); ++i)
        result.differ_primary += a.primary_hits[i].x != b.primary_hits[i].x;
    for (size_t i = 0; i < a.occluded.size(); ++i)
        result.differ_shadow += a.occluded[i] != b.occluded[i];
    for (size_t i = 0; i < a.diffuse_hits.size(); ++i)
        result.differ_diffuse += a.diffuse_hits[i].x != b.diffuse_hits[i].x;
    result.ray_count = bench.n + 2 * size_t(bench.m);
}

}  // namespace

int run_bench_build_cuda(const CudaBuildInput& in) {
    if (in.repeat < 1) throw Error("bench build: --repeat must be at least 1");
    if (in.width == 0 || in.height == 0)
        throw Error("bench build: the image size must be at least 1x1");
    const DriverApi& api = require_bench_driver();
    ContextScope ctx(api);
    const int sm = ctx.sm();
    CudaBuildResult result;
    result.in = &in;
    result.device = ctx.name();
    result.triangles = in.indices.empty() ? in.positions.size() / 3 : in.indices.size();
    GpuBvhBuildOptions options = gpu_build_options();
    // The GPU builder to compare with the host's: binned SAH (the default) or, with
    // LUCENT_GPU_BUILDER=hploc, H-PLOC.
    if (const char* b = std::getenv("LUCENT_GPU_BUILDER"); b && std::string(b) == "hploc")
        options.gpu_algorithm = GpuBuildAlgorithm::kHploc;

    // The GPU builder, on triangles already in device memory (as for geometry that moves
    // every frame): the GPU time of its kernels.
    GpuBvhBuilder builder(sm);
    DeviceBuffer positions, indices;
    const auto u0 = Clock::now();
    const DeviceTriangles device_tris =
        upload_triangles(in.positions, in.indices, positions, indices);
    result.mesh_upload_ms = ms_since(u0);
    GpuTriangleBvhDevice hploc;
    std::vector<double> gpu_ms, refit_ms;
    for (int run = -1; run < in.repeat; ++run) {
        result.hploc = builder.build(device_tris, hploc, options);
        if (run >= 0) gpu_ms.push_back(result.hploc.build_ms);
    }
    for (int run = -1; run < in.repeat; ++run) {
        const double ms = builder.refit(device_tris, hploc);
        if (run >= 0) refit_ms.push_back(ms);
    }
    result.gpu_ms = bench::rate_of(gpu_ms);
    result.refit_ms = bench::median_of(refit_ms);

    // The host binned-SAH build, its conversion to the layout and the upload.
    std::vector<double> host_ms;
    GpuTriangleBvh sah_bvh;
    GpuTriangleBvhDevice sah;
    for (int run = -1; run < in.repeat; ++run) {
        const auto t0 = Clock::now();
        sah_bvh = build_gpu_triangle_bvh(in.positions, in.indices, options);
        GpuTriangleBvhDevice fresh;  // allocation is part of the cost, as for a new scene
        upload_gpu_triangle_bvh(sah_bvh, fresh);
        check(api.cuCtxSynchronize(), "upload");
        if (run >= 0) host_ms.push_back(ms_since(t0));
        sah = std::move(fresh);
    }
    result.host_ms = bench::median_of(host_ms);
    result.host = sah_bvh.stats;

    if (in.camera && result.triangles > 0) compare_trees(api, ctx, in, sah_bvh, sah, hploc, result);
    bench::report(result, in.json);
    return 0;
}

}  // namespace lucent::cuda

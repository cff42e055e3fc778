// `lucent bench rays --backend cuda`: the host SAH tree in the GPU's layout, timed on BENCH.md's
// ray sets, then the same rays traced by TriangleAccel on the CPU; every ray's result is
// compared.
#include "bench/rays/rays_bench_cuda.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdio>
#include <thread>
#include <vector>

#include "accel/triangle_accel.h"
#include "bench/common/ray_checksums.h"
#include "bench/common/report.h"
#include "bench/gpu/ray_bench.h"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {

using bench::Json;
using bench::rate_json;
using bench::rate_text;
using bench::rounded;
using Checksums = bench::RayChecksums;

/// Runs body(i) for i in [0, count) on `threads` threads, in chunks from an atomic counter.
template <class Body>
void parallel_for(size_t count, unsigned threads, Body&& body) {
    std::atomic<size_t> next{0};
    auto worker = [&] {
        for (;;) {
            const size_t begin = next.fetch_add(256, std::memory_order_relaxed);
            if (begin >= count) return;
            const size_t end = std::min(count, begin + 256);
            for (size_t i = begin; i < end; ++i) body(i);
        }
    };
    std::vector<std::thread> pool;
    for (unsigned k = 1; k < threads; ++k) pool.emplace_back(worker);
    worker();
    for (std::thread& t : pool) t.join();
}

float3 xyz(float4 v) {
    return make_float3(v.x, v.y, v.z);
}

/// The GPU layout on the three ray sets: its rates, and every ray's result.
struct LayoutRun {
    Rate primary, shadow, diffuse;
    std::vector<uint2> primary_hits, diffuse_hits;  // (t bits, triangle), t < 0 on a miss
    std::vector<unsigned char> occluded;
};

/// Times the three ray sets on `view` and downloads what they found.
LayoutRun time_layout(RayBench& bench, const gpu::GpuTriangleBvhView& view) {
    LayoutRun run;
    run.primary = bench.time_primary(view);
    run.primary_hits.resize(bench.n);
    bench.primary_hits.download(run.primary_hits.data(), sizeof(uint2) * bench.n);
    run.shadow = bench.time_shadow(view);
    run.diffuse = bench.time_diffuse(view);
    run.occluded.resize(bench.m);
    run.diffuse_hits.resize(bench.m);
    bench.occluded.download(run.occluded.data(), bench.m);
    bench.diffuse_hits.download(run.diffuse_hits.data(), sizeof(uint2) * bench.m);
    return run;
}

/// Visits the secondary rays in pixel order (those of the pixels whose primary ray hit).
template <class Visit>
void for_secondary_in_pixel_order(const RayBench& bench, const std::vector<uint2>& primary_hits,
                                  Visit&& visit) {
    for (unsigned p = 0; p < bench.n; ++p) {
        const unsigned r = bench.ray_of_pixel[p];
        if (std::bit_cast<float>(primary_hits[r].x) >= 0.0f) visit(bench.slot[r]);
    }
}

/// The checksums of the GPU's results, summed in pixel order as the CPU bench does.
Checksums checksums_of(const RayBench& bench, const LayoutRun& run) {
    Checksums sums;
    for (unsigned p = 0; p < bench.n; ++p) {
        const float t = std::bit_cast<float>(run.primary_hits[bench.ray_of_pixel[p]].x);
        if (t >= 0.0f) ++sums.primary_hits, sums.primary_sum_t += t;
    }
    sums.shadow_rays = sums.diffuse_rays = bench.m;
    for (unsigned char b : run.occluded) sums.occluded += b;
    for_secondary_in_pixel_order(bench, run.primary_hits, [&](unsigned s) {
        const float t = std::bit_cast<float>(run.diffuse_hits[s].x);
        if (t >= 0.0f) ++sums.diffuse_hits, sums.diffuse_sum_t += t;
    });
    return sums;
}

/// The CPU backend's traversal (TriangleAccel) on the very rays the GPU made: its checksums
/// and the rays whose result differs from the GPU's.
struct CpuReference {
    Checksums sums;
    size_t differ_primary = 0, differ_shadow = 0, differ_diffuse = 0;
};

CpuReference trace_on_cpu(const CudaRaysInput& in, const RayBench& bench, const LayoutRun& gpu,
                          unsigned threads) {
    const unsigned n = bench.n, m = bench.m;
    std::vector<float4> rays_p(2 * (size_t)n), rays_s(2 * (size_t)m), rays_d(2 * (size_t)m);
    bench.primary.download(rays_p.data(), rays_p.size() * sizeof(float4));
    bench.shadow.download(rays_s.data(), rays_s.size() * sizeof(float4));
    bench.diffuse.download(rays_d.data(), rays_d.size() * sizeof(float4));
    accel::TriangleAccel cpu_accel;
    cpu_accel.build(in.positions, in.indices);
    auto cpu_closest = [&](const std::vector<float4>& rays, size_t count) {
        std::vector<float> t(count);
        parallel_for(count, threads, [&](size_t i) {
            accel::TriangleHit hit;
            const float4 o = rays[2 * i], d = rays[2 * i + 1];
            t[i] = cpu_accel.intersect(xyz(o), xyz(d), o.w, d.w, hit) ? hit.t : -1.0f;
        });
        return t;
    };
    CpuReference cpu;
    const std::vector<float> cpu_t = cpu_closest(rays_p, n);
    for (unsigned p = 0; p < n; ++p) {
        const unsigned r = bench.ray_of_pixel[p];
        if (cpu_t[r] >= 0.0f) ++cpu.sums.primary_hits, cpu.sums.primary_sum_t += cpu_t[r];
        cpu.differ_primary += std::bit_cast<float>(gpu.primary_hits[r].x) != cpu_t[r];
    }
    std::vector<unsigned char> cpu_occ(m);
    parallel_for(m, threads, [&](size_t i) {
        const float4 o = rays_s[2 * i], d = rays_s[2 * i + 1];
        cpu_occ[i] = cpu_accel.occluded(xyz(o), xyz(d), o.w, d.w);
    });
    cpu.sums.shadow_rays = cpu.sums.diffuse_rays = m;
    for (unsigned i = 0; i < m; ++i) {
        cpu.sums.occluded += cpu_occ[i];
        cpu.differ_shadow += cpu_occ[i] != gpu.occluded[i];
    }
    const std::vector<float> cpu_td = cpu_closest(rays_d, m);
    for_secondary_in_pixel_order(bench, gpu.primary_hits, [&](unsigned s) {
        if (cpu_td[s] >= 0.0f) ++cpu.sums.diffuse_hits, cpu.sums.diffuse_sum_t += cpu_td[s];
        cpu.differ_diffuse += std::bit_cast<float>(gpu.diffuse_hits[s].x) != cpu_td[s];
    });
    return cpu;
}

/// What `lucent bench rays --backend cuda` measured.
struct CudaRaysResult {
    const CudaRaysInput* in = nullptr;
    std::string device;
    int sm = 0, sm_count = 0;
    unsigned threads = 0;  // of the CPU reference
    TraceKernels kernels;
    size_t triangles = 0;
    GpuBvhStats bvh_stats;  // the host SAH tree in the GPU layout
    LayoutRun gpu_run;
    Checksums gpu;
    CpuReference cpu;
    std::string differences;  // of the checksums, gpu against cpu ("" when they agree)
};

Json to_json(const CudaRaysResult& r) {
    const CudaRaysInput& in = *r.in;
    Json primary = rate_json(r.gpu_run.primary), shadow = rate_json(r.gpu_run.shadow),
         diffuse = rate_json(r.gpu_run.diffuse);
    primary["hits"] = r.gpu.primary_hits;
    primary["sum_t"] = r.gpu.primary_sum_t;
    shadow["rays"] = r.gpu.shadow_rays;
    shadow["occluded"] = r.gpu.occluded;
    diffuse["rays"] = r.gpu.diffuse_rays;
    diffuse["hits"] = r.gpu.diffuse_hits;
    diffuse["sum_t"] = r.gpu.diffuse_sum_t;
    return Json{{"scene", in.scene},
                {"backend", "cuda"},
                {"device", r.device},
                {"sm", r.sm},
                {"triangles", r.triangles},
                {"width", in.width},
                {"height", in.height},
                {"repeat", in.repeat},
                {"persistent", r.kernels.persistent},
                {"build_ms", rounded(r.bvh_stats.build_ms + r.bvh_stats.convert_ms, 3)},
                {"bvh_nodes", r.bvh_stats.node_count},
                {"spatial_splits", in.spatial_splits},
                {"sah_cost", rounded(r.bvh_stats.sah_cost, 4)},
                {"lucent", Json{{"primary", primary}, {"shadow", shadow}, {"diffuse", diffuse}}},
                {"cpu", Json{{"primary", Json{{"hits", r.cpu.sums.primary_hits},
                                              {"sum_t", r.cpu.sums.primary_sum_t}}},
                             {"shadow", Json{{"occluded", r.cpu.sums.occluded}}},
                             {"diffuse", Json{{"hits", r.cpu.sums.diffuse_hits},
                                              {"sum_t", r.cpu.sums.diffuse_sum_t}}}}},
                {"rays_differing", Json{{"primary", r.cpu.differ_primary},
                                        {"shadow", r.cpu.differ_shadow},
                                        {"diffuse", r.cpu.differ_diffuse}}},
                {"checksums_agree", r.differences.empty()}};
}

void print_text(const CudaRaysResult& r) {
    const CudaRaysInput& in = *r.in;
    const LayoutRun& b = r.gpu_run;
    const Checksums &gpu = r.gpu, &cpu = r.cpu.sums;
    std::printf(
        "scene %s: %zu triangles, %ux%u, GPU %s (sm_%d, %d SMs), median of %d repeats, trace "
        "kernel alone (CUDA events)\n",
        in.scene.c_str(), r.triangles, in.width, in.height, r.device.c_str(), r.sm, r.sm_count,
        in.repeat);
    std::printf("kernels: %s\n", r.kernels.describe.c_str());
    std::printf(
        "build %.2f ms + convert %.2f ms (sah %.2f, %zu nodes, %zu leaves, depth %u, spatial "
        "splits %s)\n",
        r.bvh_stats.build_ms, r.bvh_stats.convert_ms, r.bvh_stats.sah_cost, r.bvh_stats.node_count,
        r.bvh_stats.leaf_count, r.bvh_stats.depth, in.spatial_splits ? "on" : "off");
    std::printf("primary %s hits=%zu sum_t=%.6e\n", rate_text(b.primary).c_str(), gpu.primary_hits,
                gpu.primary_sum_t);
    std::printf("shadow %s rays=%zu occluded=%zu\n", rate_text(b.shadow).c_str(), gpu.shadow_rays,
                gpu.occluded);
    std::printf("diffuse %s rays=%zu hits=%zu sum_t=%.6e\n", rate_text(b.diffuse).c_str(),
                gpu.diffuse_rays, gpu.diffuse_hits, gpu.diffuse_sum_t);
    std::printf(
        "cpu primary hits=%zu sum_t=%.6e, shadow occluded=%zu, diffuse hits=%zu "
        "sum_t=%.6e (TriangleAccel, %u threads, the same rays)\n",
        cpu.primary_hits, cpu.primary_sum_t, cpu.occluded, cpu.diffuse_hits, cpu.diffuse_sum_t,
        r.threads);
    if (r.differences.empty())
        std::printf("checksums: equal to the CPU backend\n");
    else
        std::printf("checksums: differ from the CPU backend: %s\n", r.differences.c_str());
    if (r.cpu.differ_primary || r.cpu.differ_shadow || r.cpu.differ_diffuse)
        std::printf(
            "rays whose result differs from the CPU: primary %zu, shadow %zu, diffuse %zu\n",
            r.cpu.differ_primary, r.cpu.differ_shadow, r.cpu.differ_diffuse);
}

/// The options of the tree the kernels trace (the environment's leaf size, see
/// gpu_build_options), with spatial splits when the input asks for Builder::kBinnedSah's tree.
GpuBvhBuildOptions build_options(const CudaRaysInput& in) {
    GpuBvhBuildOptions options = gpu_build_options();
    options.spatial_splits = in.spatial_splits;
    return options;
}

}  // namespace

int run_bench_rays_cuda(const CudaRaysInput& in) {
    if (in.width == 0 || in.height == 0)
        throw Error("bench rays: the image size must be at least 1x1");
    if (in.repeat < 1) throw Error("bench rays: --repeat must be at least 1");
    const DriverApi& api = require_bench_driver();
    ContextScope ctx(api);
    CudaRaysResult result;
    result.in = &in;
    result.threads = in.threads ? in.threads : std::max(1u, std::thread::hardware_concurrency());
    RayBench bench(api, ctx, RaySetsSpec{in.camera, in.width, in.height, in.repeat});
    result.device = ctx.name();
    result.sm = bench.sm;
    result.sm_count = bench.sm_count;
    result.kernels = bench.k;

    // The host SAH tree in the GPU layout.
    const GpuTriangleBvh bvh =
        build_gpu_triangle_bvh(in.positions, in.indices, build_options(in));
    GpuTriangleBvhDevice dbvh;
    upload_gpu_triangle_bvh(bvh, dbvh);
    result.triangles = in.indices.empty() ? in.positions.size() / 3 : in.indices.size();
    result.bvh_stats = bvh.stats;

    // The rays (BENCH.md), generated on the GPU. The CPU reference traces the very rays the
    // GPU made, so the comparison is exact even where the host compiler contracts the ray
    // formulas differently.
    bench.make_rays(dbvh.view(), triangles_by_prim(bvh));
    result.gpu_run = time_layout(bench, dbvh.view());
    result.gpu = checksums_of(bench, result.gpu_run);

    result.cpu = trace_on_cpu(in, bench, result.gpu_run, result.threads);
    result.differences = bench::checksum_differences(result.gpu, result.cpu.sums, "gpu", "cpu");
    if (in.json && in.json_out)
        *in.json_out = to_json(result);
    else
        bench::report(result, in.json);
    return 0;
}

}  // namespace lucent::cuda

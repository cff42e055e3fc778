// Compiled only with the CUDA backend (the build glob takes every bench/*.cpp).
#include "bench/bench_rays_cuda.h"
#include "bench/ray_checksums.h"

#if LUCENT_HAVE_CUDA

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <thread>
#include <vector>

#include "accel/triangle_accel.h"
#include "cuda/device/lucent_gpu/ray_order.cuh"
#include "cuda/device_buffer.h"
#include "cuda/driver_api.h"
#include "cuda/gpu_bvh_builder.h"
#include "cuda/gpu_cwbvh.h"
#include "cuda/gpu_triangle_bvh.h"
#include "cuda/nvrtc_compiler.h"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {

constexpr float kPi = 3.14159265358979323846f;

const DriverApi& require_driver() {
    std::string why;
    const DriverApi* d = driver(&why);
    if (!d)
        throw Error("--backend cuda: no NVIDIA driver or GPU usable (" + why +
                    "); run with --backend cpu");
    return *d;
}

/// The primary context of device 0, current while this object lives.
class ContextScope {
  public:
    explicit ContextScope(const DriverApi& api) : m_api(api) {
        check(api.cuDeviceGet(&m_device, 0), "cuDeviceGet");
        check(api.cuDevicePrimaryCtxRetain(&m_context, m_device), "cuDevicePrimaryCtxRetain");
        check(api.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
    }
    ~ContextScope() { m_api.cuDevicePrimaryCtxRelease(m_device); }
    ContextScope(const ContextScope&) = delete;
    ContextScope& operator=(const ContextScope&) = delete;

    CUdevice device() const { return m_device; }
    int attribute(CUdevice_attribute a) const {
        int v = 0;
        check(m_api.cuDeviceGetAttribute(&v, a, m_device), "cuDeviceGetAttribute");
        return v;
    }
    /// Compute capability x10 (90 for sm_90).
    int sm() const {
        return 10 * attribute(CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MAJOR) +
               attribute(CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MINOR);
    }
    std::string name() const {
        char buf[256] = {};
        check(m_api.cuDeviceGetName(buf, sizeof buf, m_device), "cuDeviceGetName");
        return buf;
    }

  private:
    const DriverApi& m_api;
    CUdevice m_device = 0;
    CUcontext m_context = nullptr;
};

class Module {
  public:
    Module(const DriverApi& api, const std::string& cubin) : m_api(api) {
        check(api.cuModuleLoadData(&m_module, cubin.data()), "cuModuleLoadData");
    }
    ~Module() { m_api.cuModuleUnload(m_module); }
    Module(const Module&) = delete;
    Module& operator=(const Module&) = delete;
    CUfunction function(const char* name) const {
        CUfunction f = nullptr;
        check(m_api.cuModuleGetFunction(&f, m_module, name), name);
        return f;
    }

  private:
    const DriverApi& m_api;
    CUmodule m_module = nullptr;
};

class Event {
  public:
    explicit Event(const DriverApi& api) : m_api(api) {
        check(api.cuEventCreate(&m_event, CU_EVENT_DEFAULT), "cuEventCreate");
    }
    ~Event() { m_api.cuEventDestroy(m_event); }
    Event(const Event&) = delete;
    Event& operator=(const Event&) = delete;
    CUevent get() const { return m_event; }

  private:
    const DriverApi& m_api;
    CUevent m_event = nullptr;
};

bool env_flag(const char* name, bool fallback) {
    const char* v = std::getenv(name);
    if (!v || !*v) return fallback;
    return std::strcmp(v, "0") != 0 && std::strcmp(v, "off") != 0;
}

GpuBvhBuildOptions gpu_build_options() {
    GpuBvhBuildOptions o;
    if (const char* v = std::getenv("LUCENT_GPU_LEAF_SIZE"); v && *v) {
        o.max_leaf_size = std::atoi(v);
        if (o.max_leaf_size < 1 || o.max_leaf_size > gpu::kGpuMaxLeafSize)
            throw Error("LUCENT_GPU_LEAF_SIZE=" + std::string(v) + ": expected 1.." +
                        std::to_string(gpu::kGpuMaxLeafSize));
    }
    return o;
}

double median_of(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t m = v.size();
    return m % 2 ? v[m / 2] : 0.5 * (v[m / 2 - 1] + v[m / 2]);
}

struct Rate {
    double median = 0, min = 0, max = 0;
};

/// a's median Mrays/s over b's (0 when b has none).
double median_ratio(const Rate& a, const Rate& b) {
    return b.median > 0 ? a.median / b.median : 0.0;
}

Rate rate_of(const std::vector<double>& mrays) {
    Rate r;
    if (mrays.empty()) return r;
    r.median = median_of(mrays);
    r.min = *std::min_element(mrays.begin(), mrays.end());
    r.max = *std::max_element(mrays.begin(), mrays.end());
    return r;
}

/// Checksums of one engine on the three ray sets (as the CPU bench computes them).
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

/// The compiled bench module and how to launch its trace kernels.
struct BenchKernels {
    CUfunction closest = nullptr, any = nullptr, primary_rays = nullptr, secondary_rays = nullptr;
    CUfunction cwbvh_closest = nullptr, cwbvh_any = nullptr;  // the compressed wide layout
    bool persistent = true;
    int block = 128;
    int grid_closest = 0, grid_any = 0;  // persistent grids: SMs x resident blocks
    int grid_cwbvh_closest = 0, grid_cwbvh_any = 0;
    std::string describe, describe_cwbvh;
};

CompileResult compile_bench_kernels(int sm, bool persistent) {
    // --fmad=false: ray generation rounds each operation as the host does; traversal and the
    // watertight test already spell out every fused multiply-add they use (fmaf).
    CompileRequest req =
        embedded_request("lucent_bench_kernels.cu", "#include \"lucent_gpu/bench_kernels.cuh\"\n",
                         {"--std=c++17", "--fmad=false",
                          "-DLUCENT_BENCH_PERSISTENT=" + std::string(persistent ? "1" : "0")},
                         sm);
    add_options_from_env(req, "LUCENT_BENCH_NVRTC_OPTIONS");
    return compile_cubin(req);
}

/// The bench kernels and BENCH.md's three ray sets in device memory, traced with any BVH
/// of the GPU layout: `lucent bench rays --backend cuda` times the host SAH tree with it,
/// `lucent bench build --backend cuda` compares the GPU builder's tree with that one.
class RayBench {
  public:
    RayBench(const DriverApi& api, const ContextScope& ctx, const CudaRaysInput& in)
        : m_api(api), m_in(in), m_start(api), m_stop(api) {
        sm = ctx.sm();
        sm_count = ctx.attribute(CU_DEVICE_ATTRIBUTE_MULTIPROCESSOR_COUNT);
        k.persistent = env_flag("LUCENT_BENCH_PERSISTENT", true);
        const CompileResult compiled = compile_bench_kernels(sm, k.persistent);
        m_module = std::make_unique<Module>(api, compiled.cubin);
        k.closest = m_module->function("lucent_bench_closest");
        k.any = m_module->function("lucent_bench_any");
        k.primary_rays = m_module->function("lucent_bench_primary_rays");
        k.secondary_rays = m_module->function("lucent_bench_secondary_rays");
        k.cwbvh_closest = m_module->function("lucent_bench_cwbvh_closest");
        k.cwbvh_any = m_module->function("lucent_bench_cwbvh_any");
        auto attr = [&](CUfunction f, CUfunction_attribute a) {
            int v = 0;
            check(api.cuFuncGetAttribute(&v, a, f), "cuFuncGetAttribute");
            return v;
        };
        k.block = 1 << 30;
        for (CUfunction f : {k.closest, k.any, k.cwbvh_closest, k.cwbvh_any})
            k.block = std::min(k.block, attr(f, CU_FUNC_ATTRIBUTE_MAX_THREADS_PER_BLOCK));
        auto resident = [&](CUfunction f) {
            int blocks = 0;
            check(api.cuOccupancyMaxActiveBlocksPerMultiprocessor(&blocks, f, k.block, 0),
                  "cuOccupancyMaxActiveBlocksPerMultiprocessor");
            return std::max(1, blocks);
        };
        const int res_closest = resident(k.closest), res_any = resident(k.any);
        k.grid_closest = sm_count * res_closest;
        k.grid_any = sm_count * res_any;
        const int res_cw_closest = resident(k.cwbvh_closest), res_cw_any = resident(k.cwbvh_any);
        k.grid_cwbvh_closest = sm_count * res_cw_closest;
        k.grid_cwbvh_any = sm_count * res_cw_any;
        char buf[512];
        std::snprintf(buf, sizeof buf,
                      "%s, %s, block %d; closest %d regs %d B local %d blocks/SM; any %d regs %d B "
                      "local %d blocks/SM; NVRTC %.0f ms%s",
                      k.persistent ? "persistent threads + dynamic fetch" : "one thread per ray",
                      env_flag("LUCENT_BENCH_TILES", true) ? "rays in 8x4 tiles" : "rays in rows",
                      k.block, attr(k.closest, CU_FUNC_ATTRIBUTE_NUM_REGS),
                      attr(k.closest, CU_FUNC_ATTRIBUTE_LOCAL_SIZE_BYTES), res_closest,
                      attr(k.any, CU_FUNC_ATTRIBUTE_NUM_REGS),
                      attr(k.any, CU_FUNC_ATTRIBUTE_LOCAL_SIZE_BYTES), res_any, compiled.ms,
                      compiled.from_cache ? " (cache)" : "");
        k.describe = buf;
        std::snprintf(buf, sizeof buf,
                      "closest %d regs %d B local %d blocks/SM; any %d regs %d B local %d "
                      "blocks/SM",
                      attr(k.cwbvh_closest, CU_FUNC_ATTRIBUTE_NUM_REGS),
                      attr(k.cwbvh_closest, CU_FUNC_ATTRIBUTE_LOCAL_SIZE_BYTES), res_cw_closest,
                      attr(k.cwbvh_any, CU_FUNC_ATTRIBUTE_NUM_REGS),
                      attr(k.cwbvh_any, CU_FUNC_ATTRIBUTE_LOCAL_SIZE_BYTES), res_cw_any);
        k.describe_cwbvh = buf;
        counter = DeviceBuffer(sizeof(unsigned));
    }

    /// Makes the rays: primary rays from the camera (8 x 4 tiles unless LUCENT_BENCH_TILES=0),
    /// then shadow and diffuse rays from the primary hits `view` finds, over `by_prim` (the
    /// triangles in input order, 3 float4 each).
    void make_rays(const gpu::GpuTriangleBvhView& view, const DeviceBuffer& by_prim) {
        n = m_in.width * m_in.height;
        tiled = env_flag("LUCENT_BENCH_TILES", true) ? 1 : 0;
        ray_of_pixel.assign(n, 0);
        for (unsigned r = 0; r < n; ++r)
            ray_of_pixel[tiled ? gpu::gpu_tiled_pixel(r, m_in.width, m_in.height) : r] = r;
        primary = DeviceBuffer(sizeof(float4) * 2 * n);
        primary_hits = DeviceBuffer(sizeof(uint2) * n);
        {
            const bench::Camera& cam = m_in.camera;
            const float3 fwd = normalize(cam.look - cam.eye);
            const float3 right = normalize(cross(fwd, cam.up));
            const float3 up2 = cross(right, fwd);
            float t = std::tan(cam.fov / 2 * kPi / 180);
            float a = (float)m_in.width / (float)m_in.height;
            float p[12] = {cam.eye.x, cam.eye.y, cam.eye.z, fwd.x, fwd.y, fwd.z,
                           right.x,   right.y,   right.z,   up2.x, up2.y, up2.z};
            unsigned w = m_in.width, h = m_in.height;
            CUdeviceptr rays = primary.ptr();
            void* args[] = {&p[0], &p[1],  &p[2],  &p[3], &p[4], &p[5], &p[6], &p[7],  &p[8],
                            &p[9], &p[10], &p[11], &t,    &a,    &w,    &h,    &tiled, &rays};
            launch_1d(k.primary_rays, n, args, "primary ray generation");
        }
        trace(k.closest, k.grid_closest, view, primary.ptr(), n, primary_hits.ptr());
        std::vector<uint2> hits_p(n);
        primary_hits.download(hits_p.data(), sizeof(uint2) * n);
        slot.assign(n, 0);  // primary ray -> its secondary rays
        m = 0;
        for (unsigned r = 0; r < n; ++r) {
            slot[r] = m;
            if (std::bit_cast<float>(hits_p[r].x) >= 0.0f) ++m;
        }
        // Shadow and diffuse rays from the primary hits, in pixel order.
        slots.upload(std::span<const unsigned>(slot));
        shadow = DeviceBuffer(sizeof(float4) * 2 * std::max(m, 1u));
        diffuse = DeviceBuffer(sizeof(float4) * 2 * std::max(m, 1u));
        {
            CUdeviceptr a0 = primary.ptr(), a1 = primary_hits.ptr(), a2 = slots.ptr(),
                        a3 = by_prim.ptr(), a4 = shadow.ptr(), a5 = diffuse.ptr();
            unsigned w = m_in.width, h = m_in.height;
            float lx = m_in.camera.light.x, ly = m_in.camera.light.y, lz = m_in.camera.light.z;
            void* args[] = {&a0, &a1, &a2, &a3, &w, &h, &tiled, &lx, &ly, &lz, &a4, &a5};
            launch_1d(k.secondary_rays, n, args, "secondary ray generation");
        }
        occluded = DeviceBuffer(std::max(m, 1u));
        diffuse_hits = DeviceBuffer(sizeof(uint2) * std::max(m, 1u));
    }

    /// Mrays/s of each ray set with `view` (trace kernel alone, CUDA events, `repeat` timed
    /// launches after a warm-up); the results stay in primary_hits, occluded, diffuse_hits.
    Rate time_primary(const gpu::GpuTriangleBvhView& view) {
        return time_trace(k.closest, k.grid_closest, view, primary.ptr(), n, primary_hits.ptr());
    }
    Rate time_shadow(const gpu::GpuTriangleBvhView& view) {
        return time_trace(k.any, k.grid_any, view, shadow.ptr(), m, occluded.ptr());
    }
    Rate time_diffuse(const gpu::GpuTriangleBvhView& view) {
        return time_trace(k.closest, k.grid_closest, view, diffuse.ptr(), m, diffuse_hits.ptr());
    }
    /// The same three through the compressed wide layout.
    Rate time_primary(const gpu::GpuCwbvhView& view) {
        return time_trace(k.cwbvh_closest, k.grid_cwbvh_closest, view, primary.ptr(), n,
                          primary_hits.ptr());
    }
    Rate time_shadow(const gpu::GpuCwbvhView& view) {
        return time_trace(k.cwbvh_any, k.grid_cwbvh_any, view, shadow.ptr(), m, occluded.ptr());
    }
    Rate time_diffuse(const gpu::GpuCwbvhView& view) {
        return time_trace(k.cwbvh_closest, k.grid_cwbvh_closest, view, diffuse.ptr(), m,
                          diffuse_hits.ptr());
    }

    int sm = 0, sm_count = 0;
    BenchKernels k;
    unsigned n = 0, m = 0, tiled = 1;  // primary rays; secondary rays of each kind
    std::vector<unsigned> ray_of_pixel, slot;
    DeviceBuffer primary, primary_hits, slots, shadow, diffuse, occluded, diffuse_hits;

  private:
    /// One launch of a trace kernel over a BVH view (either layout); returns its time in ms
    /// (CUDA events).
    template <class View>
    float trace(CUfunction f, int grid_persistent, View view, CUdeviceptr rays, unsigned count,
                CUdeviceptr out) {
        CUdeviceptr counter_ptr = counter.ptr();
        void* args[] = {&view, &rays, &count, &out, &counter_ptr};
        const unsigned grid =
            k.persistent ? (unsigned)grid_persistent : (count + k.block - 1) / k.block;
        counter.fill(0);
        check(m_api.cuEventRecord(m_start.get(), nullptr), "cuEventRecord");
        check(m_api.cuLaunchKernel(f, grid, 1, 1, k.block, 1, 1, 0, nullptr, args, nullptr),
              "cuLaunchKernel (trace)");
        check(m_api.cuEventRecord(m_stop.get(), nullptr), "cuEventRecord");
        check(m_api.cuEventSynchronize(m_stop.get()), "trace kernel");
        float ms = 0;
        check(m_api.cuEventElapsedTime(&ms, m_start.get(), m_stop.get()), "cuEventElapsedTime");
        return ms;
    }
    template <class View>
    Rate time_trace(CUfunction f, int grid_persistent, const View& view, CUdeviceptr rays,
                    unsigned count, CUdeviceptr out) {
        std::vector<double> mrays;
        if (count == 0) return Rate{};
        for (int run = -1; run < m_in.repeat; ++run) {
            const float ms = trace(f, grid_persistent, view, rays, count, out);
            if (run >= 0) mrays.push_back(count / (ms * 1e-3) * 1e-6);
        }
        return rate_of(mrays);
    }
    void launch_1d(CUfunction f, unsigned count, void** args, const char* what) {
        if (count == 0) return;
        check(m_api.cuLaunchKernel(f, (count + 255) / 256, 1, 1, 256, 1, 1, 0, nullptr, args,
                                   nullptr),
              what);
        check(m_api.cuCtxSynchronize(), what);
    }

    const DriverApi& m_api;
    const CudaRaysInput& m_in;
    std::unique_ptr<Module> m_module;
    DeviceBuffer counter;
    Event m_start, m_stop;
};

/// The triangles of `bvh` in input order (3 float4 each), for the secondary ray kernel.
DeviceBuffer triangles_by_prim(const GpuTriangleBvh& bvh) {
    const size_t tri_count = bvh.triangle_ids.size();
    std::vector<float4> by_prim(3 * tri_count);
    for (size_t i = 0; i < tri_count; ++i)
        for (int v = 0; v < 3; ++v) by_prim[3 * bvh.triangle_ids[i] + v] = bvh.triangles[3 * i + v];
    DeviceBuffer out;
    out.upload(std::span<const float4>(by_prim));
    return out;
}

}  // namespace

int run_bench_rays_cuda(const CudaRaysInput& in) {
    if (in.width == 0 || in.height == 0)
        throw Error("bench rays: the image size must be at least 1x1");
    if (in.repeat < 1) throw Error("bench rays: --repeat must be at least 1");
    const DriverApi& api = require_driver();
    ContextScope ctx(api);
    const unsigned threads =
        in.threads ? in.threads : std::max(1u, std::thread::hardware_concurrency());
    RayBench bench(api, ctx, in);
    const int sm = bench.sm, sm_count = bench.sm_count;
    const BenchKernels& k = bench.k;

    // The BVH.
    const GpuTriangleBvh bvh =
        build_gpu_triangle_bvh(in.positions, in.indices, gpu_build_options());
    GpuTriangleBvhDevice dbvh;
    upload_gpu_triangle_bvh(bvh, dbvh);
    const gpu::GpuTriangleBvhView view = dbvh.view();
    const size_t tri_count = bvh.triangle_ids.size();
    const DeviceBuffer tris_by_prim = triangles_by_prim(bvh);

    // The rays (BENCH.md), generated on the GPU. Checksums are summed in pixel order, as the
    // CPU bench does. The reference below traces the very rays the GPU made, so the
    // comparison is exact even where the host compiler contracts the ray formulas differently.
    bench.make_rays(view, tris_by_prim);
    const unsigned n = bench.n, m = bench.m;
    const std::vector<unsigned>& ray_of_pixel = bench.ray_of_pixel;
    const std::vector<unsigned>& slot = bench.slot;
    Checksums gpu;
    const Rate rate_primary = bench.time_primary(view);
    std::vector<uint2> hits_p(n);
    bench.primary_hits.download(hits_p.data(), sizeof(uint2) * n);
    for (unsigned p = 0; p < n; ++p) {
        const float t = std::bit_cast<float>(hits_p[ray_of_pixel[p]].x);
        if (t >= 0.0f) ++gpu.primary_hits, gpu.primary_sum_t += t;
    }
    // Visits the secondary rays in pixel order.
    auto for_secondary_in_pixel_order = [&](auto&& visit) {
        for (unsigned p = 0; p < n; ++p) {
            const unsigned r = ray_of_pixel[p];
            if (std::bit_cast<float>(hits_p[r].x) >= 0.0f) visit(slot[r]);
        }
    };
    const Rate rate_shadow = bench.time_shadow(view);
    const Rate rate_diffuse = bench.time_diffuse(view);
    std::vector<unsigned char> occ(m);
    std::vector<uint2> hits_d(m);
    bench.occluded.download(occ.data(), m);
    bench.diffuse_hits.download(hits_d.data(), sizeof(uint2) * m);
    gpu.shadow_rays = gpu.diffuse_rays = m;
    for (unsigned char b : occ) gpu.occluded += b;
    for_secondary_in_pixel_order([&](unsigned s) {
        const float t = std::bit_cast<float>(hits_d[s].x);
        if (t >= 0.0f) ++gpu.diffuse_hits, gpu.diffuse_sum_t += t;
    });

    // The compressed wide layout (cwbvh.cuh) on the same rays: its rates, and every ray's
    // result against the binary layout's (t bits and triangle; occlusion).
    const GpuCwbvh cwbvh = build_gpu_cwbvh(in.positions, in.indices);
    GpuCwbvhDevice dcwbvh;
    upload_gpu_cwbvh(cwbvh, dcwbvh);
    const Rate cw_primary = bench.time_primary(dcwbvh.view());
    std::vector<uint2> cw_hits_p(n);
    bench.primary_hits.download(cw_hits_p.data(), sizeof(uint2) * n);
    const Rate cw_shadow = bench.time_shadow(dcwbvh.view());
    const Rate cw_diffuse = bench.time_diffuse(dcwbvh.view());
    std::vector<unsigned char> cw_occ(m);
    std::vector<uint2> cw_hits_d(m);
    bench.occluded.download(cw_occ.data(), m);
    bench.diffuse_hits.download(cw_hits_d.data(), sizeof(uint2) * m);
    // A differing hit is either another distance or, at the same distance, another triangle
    // (a tie on a shared edge, which the layouts' different visiting orders break apart).
    auto same_hit = [](uint2 a, uint2 b) {
        return a.x == b.x && (std::bit_cast<float>(a.x) < 0.0f || a.y == b.y);
    };
    size_t cw_differ_p = 0, cw_differ_s = 0, cw_differ_d = 0, cw_t_p = 0, cw_t_d = 0;
    for (unsigned i = 0; i < n; ++i) {
        cw_differ_p += !same_hit(hits_p[i], cw_hits_p[i]);
        cw_t_p += hits_p[i].x != cw_hits_p[i].x;
    }
    for (unsigned i = 0; i < m; ++i) {
        cw_differ_s += occ[i] != cw_occ[i];
        cw_differ_d += !same_hit(hits_d[i], cw_hits_d[i]);
        cw_t_d += hits_d[i].x != cw_hits_d[i].x;
    }
    const double cw_mb = (cwbvh.nodes.size() * sizeof(float4)) / 1e6;
    const double binary_mb = (bvh.nodes.size() * sizeof(float4)) / 1e6;

    // The CPU backend (TriangleAccel, all threads) on the same rays.
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
    Checksums cpu;
    size_t differ_p = 0, differ_s = 0, differ_d = 0;
    const std::vector<float> cpu_t = cpu_closest(rays_p, n);
    for (unsigned p = 0; p < n; ++p) {
        const unsigned r = ray_of_pixel[p];
        if (cpu_t[r] >= 0.0f) ++cpu.primary_hits, cpu.primary_sum_t += cpu_t[r];
        differ_p += std::bit_cast<float>(hits_p[r].x) != cpu_t[r];
    }
    std::vector<unsigned char> cpu_occ(m);
    parallel_for(m, threads, [&](size_t i) {
        const float4 o = rays_s[2 * i], d = rays_s[2 * i + 1];
        cpu_occ[i] = cpu_accel.occluded(xyz(o), xyz(d), o.w, d.w);
    });
    cpu.shadow_rays = cpu.diffuse_rays = m;
    for (unsigned i = 0; i < m; ++i) {
        cpu.occluded += cpu_occ[i];
        differ_s += cpu_occ[i] != occ[i];
    }
    const std::vector<float> cpu_td = cpu_closest(rays_d, m);
    for_secondary_in_pixel_order([&](unsigned s) {
        if (cpu_td[s] >= 0.0f) ++cpu.diffuse_hits, cpu.diffuse_sum_t += cpu_td[s];
        differ_d += std::bit_cast<float>(hits_d[s].x) != cpu_td[s];
    });
    const std::string differences = bench::checksum_differences(gpu, cpu, "gpu", "cpu");

    if (in.json) {
        auto rate = [](const Rate& x) {
            char b[128];
            std::snprintf(b, sizeof b, "\"mrays\": %.4f, \"min\": %.4f, \"max\": %.4f", x.median,
                          x.min, x.max);
            return std::string(b);
        };
        std::printf(
            "{\"scene\": \"%s\", \"backend\": \"cuda\", \"device\": \"%s\", \"sm\": %d, "
            "\"triangles\": %zu, \"width\": %u, \"height\": %u, \"repeat\": %d, "
            "\"persistent\": %s, \"build_ms\": %.3f, \"bvh_nodes\": %zu, \"sah_cost\": %.4f,\n"
            " \"lucent\": {\"primary\": {%s, \"hits\": %zu, \"sum_t\": %.9e}, "
            "\"shadow\": {%s, \"rays\": %zu, \"occluded\": %zu}, "
            "\"diffuse\": {%s, \"rays\": %zu, \"hits\": %zu, \"sum_t\": %.9e}},\n"
            " \"cpu\": {\"primary\": {\"hits\": %zu, \"sum_t\": %.9e}, \"shadow\": {\"occluded\": "
            "%zu}, \"diffuse\": {\"hits\": %zu, \"sum_t\": %.9e}},\n"
            " \"rays_differing\": {\"primary\": %zu, \"shadow\": %zu, \"diffuse\": %zu}, "
            "\"checksums_agree\": %s,\n"
            " \"cwbvh\": {\"nodes\": %zu, \"node_mb\": %.4f, \"binary_node_mb\": %.4f, "
            "\"build_ms\": %.3f, \"primary\": {%s}, \"shadow\": {%s}, \"diffuse\": {%s}, "
            "\"rays_differing_from_binary\": {\"primary\": %zu, \"shadow\": %zu, \"diffuse\": "
            "%zu}, \"distances_differing_from_binary\": {\"primary\": %zu, \"diffuse\": %zu}}}\n",
            in.scene.c_str(), ctx.name().c_str(), sm, tri_count, in.width, in.height, in.repeat,
            k.persistent ? "true" : "false", bvh.stats.build_ms + bvh.stats.convert_ms,
            bvh.stats.node_count, bvh.stats.sah_cost, rate(rate_primary).c_str(), gpu.primary_hits,
            gpu.primary_sum_t, rate(rate_shadow).c_str(), gpu.shadow_rays, gpu.occluded,
            rate(rate_diffuse).c_str(), gpu.diffuse_rays, gpu.diffuse_hits, gpu.diffuse_sum_t,
            cpu.primary_hits, cpu.primary_sum_t, cpu.occluded, cpu.diffuse_hits, cpu.diffuse_sum_t,
            differ_p, differ_s, differ_d, differences.empty() ? "true" : "false",
            cwbvh.stats.node_count, cw_mb, binary_mb,
            cwbvh.stats.build_ms + cwbvh.stats.convert_ms, rate(cw_primary).c_str(),
            rate(cw_shadow).c_str(), rate(cw_diffuse).c_str(), cw_differ_p, cw_differ_s,
            cw_differ_d, cw_t_p, cw_t_d);
        return 0;
    }
    auto rate_text = [](const Rate& r) {
        char buf[128];
        std::snprintf(buf, sizeof buf, "%.2f Mrays/s (min %.2f, max %.2f)", r.median, r.min, r.max);
        return std::string(buf);
    };
    std::printf(
        "scene %s: %zu triangles, %ux%u, GPU %s (sm_%d, %d SMs), median of %d repeats, trace "
        "kernel alone (CUDA events)\n",
        in.scene.c_str(), tri_count, in.width, in.height, ctx.name().c_str(), sm, sm_count,
        in.repeat);
    std::printf("kernels: %s\n", k.describe.c_str());
    std::printf("build %.2f ms + convert %.2f ms (sah %.2f, %zu nodes, %zu leaves, depth %u)\n",
                bvh.stats.build_ms, bvh.stats.convert_ms, bvh.stats.sah_cost, bvh.stats.node_count,
                bvh.stats.leaf_count, bvh.stats.depth);
    std::printf("primary %s hits=%zu sum_t=%.6e\n", rate_text(rate_primary).c_str(),
                gpu.primary_hits, gpu.primary_sum_t);
    std::printf("shadow %s rays=%zu occluded=%zu\n", rate_text(rate_shadow).c_str(),
                gpu.shadow_rays, gpu.occluded);
    std::printf("diffuse %s rays=%zu hits=%zu sum_t=%.6e\n", rate_text(rate_diffuse).c_str(),
                gpu.diffuse_rays, gpu.diffuse_hits, gpu.diffuse_sum_t);
    std::printf("compressed wide layout (cwbvh): %zu nodes, %.2f MB of nodes (binary %.2f MB), "
                "build %.1f ms; %s\n",
                cwbvh.stats.node_count, cw_mb, binary_mb,
                cwbvh.stats.build_ms + cwbvh.stats.convert_ms, k.describe_cwbvh.c_str());
    std::printf("cwbvh primary %s (%.3fx binary)\n", rate_text(cw_primary).c_str(),
                median_ratio(cw_primary, rate_primary));
    std::printf("cwbvh shadow %s (%.3fx binary)\n", rate_text(cw_shadow).c_str(),
                median_ratio(cw_shadow, rate_shadow));
    std::printf("cwbvh diffuse %s (%.3fx binary)\n", rate_text(cw_diffuse).c_str(),
                median_ratio(cw_diffuse, rate_diffuse));
    std::printf("cwbvh results differing from the binary layout's: primary %zu, shadow %zu, "
                "diffuse %zu; of them another distance: primary %zu, diffuse %zu (the rest: "
                "another triangle at the same distance)\n",
                cw_differ_p, cw_differ_s, cw_differ_d, cw_t_p, cw_t_d);
    std::printf(
        "cpu primary hits=%zu sum_t=%.6e, shadow occluded=%zu, diffuse hits=%zu "
        "sum_t=%.6e (TriangleAccel, %u threads, the same rays)\n",
        cpu.primary_hits, cpu.primary_sum_t, cpu.occluded, cpu.diffuse_hits, cpu.diffuse_sum_t,
        threads);
    if (differences.empty())
        std::printf("checksums: equal to the CPU backend\n");
    else
        std::printf("checksums: differ from the CPU backend: %s\n", differences.c_str());
    if (differ_p || differ_s || differ_d)
        std::printf(
            "rays whose result differs from the CPU: primary %zu, shadow %zu, diffuse %zu\n",
            differ_p, differ_s, differ_d);
    return 0;
}

int run_bench_build_cuda(const CudaBuildInput& in) {
    if (in.repeat < 1) throw Error("bench build: --repeat must be at least 1");
    if (in.width == 0 || in.height == 0)
        throw Error("bench build: the image size must be at least 1x1");
    const DriverApi& api = require_driver();
    ContextScope ctx(api);
    const int sm = ctx.sm();
    const size_t tris = in.indices.empty() ? in.positions.size() / 3 : in.indices.size();
    const GpuBvhBuildOptions options = gpu_build_options();

    // The GPU builder, on triangles already in device memory (as for geometry that moves
    // every frame): the GPU time of its kernels.
    GpuBvhBuilder builder(sm);
    DeviceBuffer positions, indices;
    const auto u0 = std::chrono::steady_clock::now();
    const DeviceTriangles device_tris =
        upload_triangles(in.positions, in.indices, positions, indices);
    const double mesh_upload_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - u0).count();
    GpuTriangleBvhDevice hploc;
    GpuBvhStats hploc_stats;
    std::vector<double> gpu_ms, refit_ms;
    for (int run = -1; run < in.repeat; ++run) {
        hploc_stats = builder.build(device_tris, hploc, options);
        if (run >= 0) gpu_ms.push_back(hploc_stats.build_ms);
    }
    for (int run = -1; run < in.repeat; ++run) {
        const double ms = builder.refit(device_tris, hploc);
        if (run >= 0) refit_ms.push_back(ms);
    }

    // The host binned-SAH build, its conversion to the layout and the upload.
    std::vector<double> host_ms;
    GpuTriangleBvh sah_bvh;
    GpuTriangleBvhDevice sah;
    for (int run = -1; run < in.repeat; ++run) {
        const auto t0 = std::chrono::steady_clock::now();
        sah_bvh = build_gpu_triangle_bvh(in.positions, in.indices, options);
        GpuTriangleBvhDevice fresh;  // allocation is part of the cost, as for a new scene
        upload_gpu_triangle_bvh(sah_bvh, fresh);
        check(api.cuCtxSynchronize(), "upload");
        const auto t1 = std::chrono::steady_clock::now();
        if (run >= 0) host_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
        sah = std::move(fresh);
    }

    // Both trees on the same rays; every hit compared.
    struct Rates {
        Rate primary, shadow, diffuse;
    } rates_sah, rates_hploc;
    size_t differ_p = 0, differ_s = 0, differ_d = 0, ray_count = 0;
    if (in.camera && tris > 0) {
        CudaRaysInput rin;
        rin.camera = *in.camera;
        rin.width = in.width, rin.height = in.height, rin.repeat = in.repeat;
        RayBench bench(api, ctx, rin);
        const DeviceBuffer by_prim = triangles_by_prim(sah_bvh);
        bench.make_rays(sah.view(), by_prim);
        auto run_all = [&](const gpu::GpuTriangleBvhView& view, Rates& r, std::vector<uint2>& hp,
                           std::vector<unsigned char>& occ, std::vector<uint2>& hd) {
            r.primary = bench.time_primary(view);
            r.shadow = bench.time_shadow(view);
            r.diffuse = bench.time_diffuse(view);
            hp.resize(bench.n), occ.resize(bench.m), hd.resize(bench.m);
            bench.primary_hits.download(hp.data(), sizeof(uint2) * hp.size());
            bench.occluded.download(occ.data(), occ.size());
            bench.diffuse_hits.download(hd.data(), sizeof(uint2) * hd.size());
        };
        std::vector<uint2> hp_a, hd_a, hp_b, hd_b;
        std::vector<unsigned char> occ_a, occ_b;
        run_all(sah.view(), rates_sah, hp_a, occ_a, hd_a);
        run_all(hploc.view(), rates_hploc, hp_b, occ_b, hd_b);
        for (size_t i = 0; i < hp_a.size(); ++i) differ_p += hp_a[i].x != hp_b[i].x;
        for (size_t i = 0; i < occ_a.size(); ++i) differ_s += occ_a[i] != occ_b[i];
        for (size_t i = 0; i < hd_a.size(); ++i) differ_d += hd_a[i].x != hd_b[i].x;
        ray_count = bench.n + 2 * size_t(bench.m);
    }

    const double ms = median_of(gpu_ms);
    const double lo = *std::min_element(gpu_ms.begin(), gpu_ms.end());
    const double hi = *std::max_element(gpu_ms.begin(), gpu_ms.end());
    const double host = median_of(host_ms);
    if (in.json) {
        std::printf(
            "{\"scene\": \"%s\", \"backend\": \"cuda\", \"device\": \"%s\", \"triangles\": %zu, "
            "\"builder\": \"%s\", \"build_ms\": %.4f, \"min_ms\": %.4f, \"max_ms\": %.4f, "
            "\"mtris_per_s\": %.3f, \"sah_cost\": %.4f, \"nodes\": %zu, \"depth\": %u, "
            "\"refit_ms\": %.4f, \"mesh_upload_ms\": %.3f, \"host_sah_ms\": %.3f, "
            "\"host_sah_cost\": %.4f",
            in.scene.c_str(), ctx.name().c_str(), tris, hploc_stats.builder, ms, lo, hi,
            tris / ms * 1e-3, hploc_stats.sah_cost, hploc_stats.node_count, hploc_stats.depth,
            median_of(refit_ms), mesh_upload_ms, host, sah_bvh.stats.sah_cost);
        if (ray_count)
            std::printf(
                ", \"width\": %u, \"height\": %u, \"mrays\": {\"primary\": %.2f, \"shadow\": "
                "%.2f, \"diffuse\": %.2f}, \"host_sah_mrays\": {\"primary\": %.2f, \"shadow\": "
                "%.2f, \"diffuse\": %.2f}, \"rays_differing\": %zu",
                in.width, in.height, rates_hploc.primary.median, rates_hploc.shadow.median,
                rates_hploc.diffuse.median, rates_sah.primary.median, rates_sah.shadow.median,
                rates_sah.diffuse.median, differ_p + differ_s + differ_d);
        std::printf("}\n");
        return 0;
    }
    std::printf("scene %s: %zu triangles, GPU %s, median of %d builds\n", in.scene.c_str(), tris,
                ctx.name().c_str(), in.repeat);
    std::printf(
        "GPU build (%s) %.3f ms (min %.3f, max %.3f) %.1f Mtris/s sah=%.3f nodes=%zu depth=%u "
        "(GPU time of its kernels; the mesh upload %.2f ms is apart)\n",
        hploc_stats.builder, ms, lo, hi, tris / ms * 1e-3, hploc_stats.sah_cost,
        hploc_stats.node_count, hploc_stats.depth, mesh_upload_ms);
    std::printf("GPU refit %.3f ms\n", median_of(refit_ms));
    std::printf(
        "host build (binned SAH + layout + upload) %.2f ms %.2f Mtris/s sah=%.3f nodes=%zu "
        "depth=%u\n",
        host, tris / host * 1e-3, sah_bvh.stats.sah_cost, sah_bvh.stats.node_count,
        sah_bvh.stats.depth);
    if (ray_count) {
        std::printf("rays %ux%u (BENCH.md sets), Mrays/s, GPU-built tree / host SAH tree:\n",
                    in.width, in.height);
        std::printf("primary %.2f / %.2f (%.3fx)\n", rates_hploc.primary.median,
                    rates_sah.primary.median, median_ratio(rates_hploc.primary, rates_sah.primary));
        std::printf("shadow %.2f / %.2f (%.3fx)\n", rates_hploc.shadow.median,
                    rates_sah.shadow.median, median_ratio(rates_hploc.shadow, rates_sah.shadow));
        std::printf("diffuse %.2f / %.2f (%.3fx)\n", rates_hploc.diffuse.median,
                    rates_sah.diffuse.median, median_ratio(rates_hploc.diffuse, rates_sah.diffuse));
        std::printf(
            "hits: %zu of %zu rays differ between the trees (primary %zu, shadow %zu, "
            "diffuse %zu)\n",
            differ_p + differ_s + differ_d, ray_count, differ_p, differ_s, differ_d);
    } else {
        std::printf("no rays traced: no viewpoint for this scene (cameras.txt)\n");
    }
    return 0;
}

}  // namespace lucent::cuda

#endif  // LUCENT_HAVE_CUDA

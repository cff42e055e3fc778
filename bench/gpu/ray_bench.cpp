#include "bench/gpu/ray_bench.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "bench/gpu/bench_sources.h"
#include "cuda/device/lucent_gpu/ray_order.cuh"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {
constexpr float kPi = 3.14159265358979323846f;
}  // namespace

bool env_flag(const char* name, bool fallback) {
    const char* v = std::getenv(name);
    if (!v || !*v) return fallback;
    return std::strcmp(v, "0") != 0 && std::strcmp(v, "off") != 0;
}

GpuBvhBuildOptions gpu_build_options() {
    GpuBvhBuildOptions o;
    o.spatial_splits = false;  // the GPU builder's tree; callers turn them on
    if (const char* v = std::getenv("LUCENT_GPU_LEAF_SIZE"); v && *v) {
        o.max_leaf_size = std::atoi(v);
        if (o.max_leaf_size < 1 || o.max_leaf_size > gpu::kGpuMaxLeafSize)
            throw Error("LUCENT_GPU_LEAF_SIZE=" + std::string(v) + ": expected 1.." +
                        std::to_string(gpu::kGpuMaxLeafSize));
    }
    return o;
}

CompileResult compile_trace_kernels(int sm, bool persistent) {
    // --fmad=false: ray generation rounds each operation as the host does; traversal and the
    // watertight test already spell out every fused multiply-add they use (fmaf).
    CompileRequest req = bench_kernel_request(
        "lucent_bench_kernels.cu", "#include \"lucent_bench/trace_kernels.cuh\"\n",
        {"--std=c++17", "--fmad=false",
         "-DLUCENT_BENCH_PERSISTENT=" + std::string(persistent ? "1" : "0")},
        sm);
    add_options_from_env(req, "LUCENT_BENCH_NVRTC_OPTIONS");
    return compile_cubin(req);
}

RayBench::RayBench(const DriverApi& api, const ContextScope& ctx, const RaySetsSpec& spec)
    : m_api(api), m_in(spec), m_start(api), m_stop(api) {
    sm = ctx.sm();
    sm_count = ctx.attribute(CU_DEVICE_ATTRIBUTE_MULTIPROCESSOR_COUNT);
    k.persistent = env_flag("LUCENT_BENCH_PERSISTENT", true);
    const CompileResult compiled = compile_trace_kernels(sm, k.persistent);
    m_module = std::make_unique<Module>(api, compiled.cubin);
    k.closest = m_module->function("lucent_bench_closest");
    k.any = m_module->function("lucent_bench_any");
    k.primary_rays = m_module->function("lucent_bench_primary_rays");
    k.secondary_rays = m_module->function("lucent_bench_secondary_rays");
    auto attr = [&](CUfunction f, CUfunction_attribute a) {
        int v = 0;
        check(api.cuFuncGetAttribute(&v, a, f), "cuFuncGetAttribute");
        return v;
    };
    k.block = 1 << 30;
    for (CUfunction f : {k.closest, k.any})
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
    counter = DeviceBuffer(sizeof(unsigned));
}

void RayBench::make_rays(const gpu::GpuTriangleBvhView& view, const DeviceBuffer& by_prim) {
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

DeviceBuffer triangles_by_prim(const GpuTriangleBvh& bvh) {
    // With spatial splits a triangle fills several leaf slots: size by the largest index.
    size_t tri_count = 0;
    for (uint32_t id : bvh.triangle_ids) tri_count = std::max<size_t>(tri_count, size_t(id) + 1);
    std::vector<float4> by_prim(3 * tri_count);
    for (size_t i = 0; i < bvh.triangle_ids.size(); ++i)
        for (int v = 0; v < 3; ++v) by_prim[3 * bvh.triangle_ids[i] + v] = bvh.triangles[3 * i + v];
    DeviceBuffer out;
    out.upload(std::span<const float4>(by_prim));
    return out;
}

}  // namespace lucent::cuda

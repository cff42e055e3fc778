// BENCH.md's three ray sets in device memory and the bench's trace kernels
// (device/lucent_bench/trace_kernels.cuh) that time them over a BVH of the GPU layout:
// `lucent bench rays --backend cuda` times the host SAH tree with them, `lucent bench build
// --backend cuda` compares the GPU builder's tree with that one.
#pragma once

#include <cuda.h>

#include <memory>
#include <string>
#include <vector>

#include "bench/common/bench_camera.h"
#include "bench/common/rate.h"
#include "bench/gpu/gpu_session.h"
#include "cuda/accel/gpu_bvh_builder.h"
#include "cuda/accel/gpu_triangle_bvh.h"
#include "cuda/backend/device_buffer.h"
#include "cuda/jit/nvrtc_compiler.h"

namespace lucent::cuda {

using bench::Rate;
using bench::rate_of;

/// Whether environment variable `name` is set to anything but 0 or off (`fallback` unset).
bool env_flag(const char* name, bool fallback);

/// The GPU layout's build options: LUCENT_GPU_LEAF_SIZE=1..8 (default 4), no spatial splits
/// (the tree the GPU builder makes from the same triangles).
GpuBvhBuildOptions gpu_build_options();

/// The compiled bench module and how to launch its trace kernels.
struct TraceKernels {
    CUfunction closest = nullptr, any = nullptr, primary_rays = nullptr, secondary_rays = nullptr;
    bool persistent = true;
    int block = 128;
    int grid_closest = 0, grid_any = 0;  // persistent grids: SMs x resident blocks
    std::string describe;
};

/// The trace kernels for compute capability `sm` (x10), persistent threads or one per ray.
CompileResult compile_trace_kernels(int sm, bool persistent);

/// The rays' shape: a camera, an image size, and how many timed launches each set gets.
struct RaySetsSpec {
    bench::Camera camera;
    unsigned width = 3840, height = 2160;
    int repeat = 5;
};

/// The bench kernels and BENCH.md's three ray sets in device memory, traced with any BVH
/// of the GPU layout: `lucent bench rays --backend cuda` times the host SAH tree with it,
/// `lucent bench build --backend cuda` compares the GPU builder's tree with that one.
class RayBench {
  public:
    /// Compiles the trace kernels for the current context's GPU and sizes their grids.
    RayBench(const DriverApi& api, const ContextScope& ctx, const RaySetsSpec& spec);

    /// Makes the rays: primary rays from the camera (8 x 4 tiles unless LUCENT_BENCH_TILES=0),
    /// then shadow and diffuse rays from the primary hits `view` finds, over `by_prim` (the
    /// triangles in input order, 3 float4 each).
    void make_rays(const gpu::GpuTriangleBvhView& view, const DeviceBuffer& by_prim);

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

    int sm = 0, sm_count = 0;
    TraceKernels k;
    unsigned n = 0, m = 0, tiled = 1;  // primary rays; secondary rays of each kind
    std::vector<unsigned> ray_of_pixel, slot;
    DeviceBuffer primary, primary_hits, slots, shadow, diffuse, occluded, diffuse_hits;

  private:
    /// One launch of a trace kernel over a BVH view; returns its time in ms (CUDA events).
    float trace(CUfunction f, int grid_persistent, gpu::GpuTriangleBvhView view, CUdeviceptr rays,
                unsigned count, CUdeviceptr out) {
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
    Rate time_trace(CUfunction f, int grid_persistent, const gpu::GpuTriangleBvhView& view,
                    CUdeviceptr rays, unsigned count, CUdeviceptr out) {
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
    const RaySetsSpec m_in;
    std::unique_ptr<Module> m_module;
    DeviceBuffer counter;
    Event m_start, m_stop;
};

/// The triangles of `bvh` in input order (3 float4 each), for the secondary ray kernel.
DeviceBuffer triangles_by_prim(const GpuTriangleBvh& bvh);

}  // namespace lucent::cuda

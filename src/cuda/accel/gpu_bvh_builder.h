// Builds the GPU triangle BVH layout (triangle_bvh.cuh) on the GPU itself, for geometry
// that changes every frame, and a GPU refit of any layout (bvh_refit.cuh). Two algorithms
// (GpuBvhBuildOptions::gpu_algorithm): binned SAH (bvh_sah_build.cuh, the default), the
// host's algorithm and tree, 1.1 ms for Sponza; H-PLOC (bvh_build.cuh), trees tracing at
// 0.85-1.05x the SAH tree's speed, built in 0.3 ms for Sponza and 2 ms for a million
// triangles (H200, docs/performance.md).
#pragma once

#include <cuda.h>

#include <memory>
#include <span>

#include "cuda/accel/gpu_triangle_bvh.h"
#include "cuda/jit/nvrtc_compiler.h"
#include "lucent/error.h"

namespace lucent::cuda {

/// Triangles in device memory: `vertex_count` float3 positions and `triangle_count` uint3
/// indices, or no indices (indices == 0: triangle i is vertices 3i .. 3i + 2).
struct DeviceTriangles {
    CUdeviceptr positions = 0;
    unsigned vertex_count = 0;
    CUdeviceptr indices = 0;
    unsigned triangle_count = 0;
};

/// Copies host triangles (indices may be empty) into `positions_out` and `indices_out` and
/// describes them.
DeviceTriangles upload_triangles(std::span<const float3> positions, std::span<const uint3> indices,
                                 DeviceBuffer& positions_out, DeviceBuffer& indices_out);

/// A tree deeper than the GPU traversal stack: agglomerative builds can chain (triangles in a
/// geometric progression do); the host SAH builder bounds its depth and can take the mesh.
class GpuBvhTooDeep : public Error {
  public:
    using Error::Error;
};

/// The NVRTC request of the build kernels' module for `sm` (compute capability x 10): what
/// GpuBvhBuilder compiles, also compiled without a GPU by gpu_bvh_builder_test.
CompileRequest bvh_builder_request(int sm);

/// One builder per CUDA context (it holds that context's module and scratch memory); use it
/// with that context current. Not thread-safe.
class GpuBvhBuilder {
  public:
    /// Compiles the build kernels with NVRTC for `sm` (or loads them from the kernel cache).
    explicit GpuBvhBuilder(int sm);
    ~GpuBvhBuilder();
    GpuBvhBuilder(const GpuBvhBuilder&) = delete;
    GpuBvhBuilder& operator=(const GpuBvhBuilder&) = delete;

    /// Allocates ahead what a binned-SAH build of up to `triangles` triangles needs: its
    /// scratch, and a layout that the first build into an empty GpuTriangleBvhDevice takes.
    /// Allocating device memory is a sizeable part of a first build (Sponza on an H200:
    /// 0.23-0.31 ms, against 1.1-1.2 ms for the build's kernels; docs/performance.md); done
    /// ahead, on another thread while the application loads its scene, the first build
    /// starts at once. Throws lucent::Error when
    /// the memory cannot be had; a build then allocates what it needs itself.
    void prepare(unsigned triangles);

    /// Builds over triangles already on the device, into `out` (its buffers are reused when
    /// big enough). stats.build_ms is the GPU time of the build kernels (CUDA events).
    /// Throws lucent::Error for an index out of range (naming the triangle), GpuBvhTooDeep for
    /// a tree too deep for the traversal stack.
    GpuBvhStats build(const DeviceTriangles& triangles, GpuTriangleBvhDevice& out,
                      const GpuBvhBuildOptions& options = {});
    /// Uploads host triangles (indices may be empty), then builds as above.
    GpuBvhStats build(std::span<const float3> positions, std::span<const uint3> indices,
                      GpuTriangleBvhDevice& out, const GpuBvhBuildOptions& options = {});

    /// Gathers triangles of several instances (`pieces`, in device memory) into one mesh:
    /// vertices concatenated, indices rebased onto them (lucent_gather_triangles). The mesh
    /// is the builder's scratch, valid until the next gather.
    DeviceTriangles gather(std::span<const DeviceTriangles> pieces);

    /// Moves `bvh`'s triangles to new vertex positions (the same triangles, in the same
    /// order, as it was built from) and recomputes its boxes; returns the GPU time in ms.
    double refit(const DeviceTriangles& triangles, GpuTriangleBvhDevice& bvh);
    double refit(std::span<const float3> positions, std::span<const uint3> indices,
                 GpuTriangleBvhDevice& bvh);

  private:
    struct Impl;
    std::unique_ptr<Impl> m;
};

}  // namespace lucent::cuda

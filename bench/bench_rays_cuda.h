// `lucent bench rays --backend cuda` and `lucent bench build --backend cuda`: the ray sets
// of shared/BENCH.md traced on the GPU with the Aila-Laine traversal of
// src/cuda/device/lucent_gpu/triangle_bvh.cuh, checked against TriangleAccel on the CPU.
// The header needs no CUDA headers; the functions exist when LUCENT_HAVE_CUDA is defined.
#pragma once

#include <optional>
#include <span>
#include <string>

#include "bench/bench_camera.h"
#include "lucent/device/vector_math.h"

namespace lucent::cuda {

struct CudaRaysInput {
    std::string scene;  // for the report
    std::span<const float3> positions;
    std::span<const uint3> indices;
    bench::Camera camera;
    unsigned width = 3840, height = 2160;
    int repeat = 5;
    unsigned threads = 0;  // CPU threads of the reference trace, 0 = all
    bool json = false;
};

/// Times the trace kernels (CUDA events, median of `repeat` after a warm-up), prints one
/// line per ray kind in the CPU bench's format, and the comparison with the CPU backend on
/// the same rays. Throws lucent::Error without a driver or GPU. Returns the exit code.
/// Environment: LUCENT_BENCH_PERSISTENT=0 (plain grid instead of persistent threads),
/// LUCENT_BENCH_TILES=0 (rays in pixel order instead of 8x4 tiles; checksums unchanged),
/// LUCENT_GPU_LEAF_SIZE=1..8 (default 4), LUCENT_BENCH_NVRTC_OPTIONS (extra NVRTC options,
/// e.g. "-DLUCENT_BENCH_MIN_BLOCKS=6 -DLUCENT_GPU_DYNAMIC_FETCH_THRESHOLD=16").
int run_bench_rays_cuda(const CudaRaysInput& input);

struct CudaBuildInput {
    std::string scene;
    std::span<const float3> positions;
    std::span<const uint3> indices;
    int repeat = 5;
    bool json = false;
    // The ray sets both trees are timed on; no rays are traced without a camera.
    std::optional<bench::Camera> camera;
    unsigned width = 3840, height = 2160;
};

/// Times the GPU builder (H-PLOC, GPU time of its kernels, median) and its refit, and the
/// host binned-SAH build + conversion + upload; prints Mtris/s and SAH cost of both, and the
/// Mrays/s each tree gives on BENCH.md's ray sets (with hits compared ray by ray).
int run_bench_build_cuda(const CudaBuildInput& input);

}  // namespace lucent::cuda

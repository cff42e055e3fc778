// `lucent bench rays --backend cuda`: the ray sets of shared/BENCH.md traced on the GPU with
// the Aila-Laine traversal of src/cuda/device/lucent_gpu/triangle_bvh.cuh, checked against
// TriangleAccel on the CPU. The header needs no CUDA headers; the function exists when
// LUCENT_HAVE_CUDA is defined.
#pragma once

#include <span>
#include <string>

#include "bench/common/bench_camera.h"
#include "bench/common/report.h"
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
    // The tree the kernels trace: the host's binned SAH, with spatial splits (what
    // Builder::kBinnedSah, and Builder::kAuto once upgraded, give the CUDA backend) or without
    // (the tree the GPU builder makes, Builder::kAuto's before its upgrade).
    bool spatial_splits = false;
    bool json = false;
    /// With `json`: where the document goes instead of stdout (the caller adds to it, e.g.
    /// `--programs`' figures, and prints one document).
    bench::Json* json_out = nullptr;
};

/// Times the trace kernels (CUDA events, median of `repeat` after a warm-up), prints one
/// line per ray kind in the CPU bench's format, and the comparison with the CPU backend on
/// the same rays. Throws lucent::Error without a driver or GPU. Returns the exit code.
/// Environment: LUCENT_BENCH_PERSISTENT=0 (plain grid instead of persistent threads),
/// LUCENT_BENCH_TILES=0 (rays in pixel order instead of 8x4 tiles, for the kernels and
/// --programs alike; checksums unchanged),
/// LUCENT_GPU_LEAF_SIZE=1..8 (default 4), LUCENT_BENCH_NVRTC_OPTIONS (extra NVRTC options,
/// e.g. "-DLUCENT_BENCH_MIN_BLOCKS=6 -DLUCENT_GPU_DYNAMIC_FETCH_THRESHOLD=16").
int run_bench_rays_cuda(const CudaRaysInput& input);

}  // namespace lucent::cuda

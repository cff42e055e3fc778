// `lucent bench build --backend cuda`: the GPU builder (H-PLOC) against the host binned-SAH
// build, and the rays of shared/BENCH.md traced through both trees. The header needs no CUDA
// headers; the function exists when LUCENT_HAVE_CUDA is defined.
#pragma once

#include <optional>
#include <span>
#include <string>

#include "bench/common/bench_camera.h"
#include "lucent/device/vector_math.h"

namespace lucent::cuda {

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

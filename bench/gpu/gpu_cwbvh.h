// Host side of the compressed wide GPU BVH (device/lucent_bench/cwbvh.cuh): the
// optimal 8-wide collapse of the binned-SAH binary BVH, with child boxes quantized to 8 bits
// per plane on each node's own grid.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "bench/gpu/device/lucent_bench/cwbvh.cuh"
#include "cuda/accel/gpu_triangle_bvh.h"

namespace lucent::cuda {

/// The compressed wide layout in host memory (see cwbvh.cuh for the format).
struct GpuCwbvh {
    std::vector<float4> nodes;           // 5 per node, root first
    std::vector<float4> triangles;       // 3 per triangle, leaf order
    std::vector<uint32_t> triangle_ids;  // leaf order -> input order
    GpuBvhStats stats;                   // node_count: wide nodes

    /// A view over these host arrays: lets the host run the GPU traversal (tests).
    gpu::GpuCwbvhView host_view() const {
        return {nodes.data(), triangles.data(), triangle_ids.data()};
    }
};

/// The binary layout's build options with leaves of up to three triangles: the paper's, and
/// what a leaf's unary count holds.
inline GpuBvhBuildOptions cwbvh_build_options() {
    GpuBvhBuildOptions options;
    options.max_leaf_size = gpu::kCwbvhMaxLeafSize;
    return options;
}

/// Builds over triangles (indices may be empty: then triangle i is vertices 3i..3i+2), with
/// leaves of at most options.max_leaf_size (1..3) triangles. Throws lucent::Error for an
/// index out of range, a non-finite vertex, or a mesh too big for the format.
GpuCwbvh build_gpu_cwbvh(std::span<const float3> positions, std::span<const uint3> indices,
                         const GpuBvhBuildOptions& options = cwbvh_build_options());

/// The grid of one axis of a node: planes are origin + q * 2^(biased_exponent - 127) for
/// q in 0..255, every one of them a float (origin is a multiple of the step, and
/// |origin| / step + 255 < 2^24), and the grid reaches from lo to at least hi.
struct CwbvhAxisGrid {
    float origin;
    unsigned biased_exponent;
};
CwbvhAxisGrid cwbvh_axis_grid(float lo, float hi);

/// A GpuCwbvh in device memory.
struct GpuCwbvhDevice {
    DeviceBuffer nodes, triangles, triangle_ids;
    /// Device pointers, to pass to kernels by value.
    gpu::GpuCwbvhView view() const {
        return {nodes.as<float4>(), triangles.as<float4>(), triangle_ids.as<unsigned>()};
    }
};

/// Uploads (synchronously) into `device`, reusing its buffers when the sizes match.
void upload_gpu_cwbvh(const GpuCwbvh& bvh, GpuCwbvhDevice& device);

}  // namespace lucent::cuda

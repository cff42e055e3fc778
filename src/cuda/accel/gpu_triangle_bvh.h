// Host side of the GPU triangle BVH (src/cuda/device/lucent_gpu/triangle_bvh.cuh): builds
// the layout from a mesh with the engine's binned-SAH Bvh, and uploads it.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "accel/bvh.h"
#include "cuda/backend/device_buffer.h"
#include "cuda/device/lucent_gpu/triangle_bvh.cuh"

namespace lucent::cuda {

/// What GpuBvhBuilder runs on the GPU: the host's binned-SAH algorithm (the same tree as
/// build_gpu_triangle_bvh, bvh_sah_build.cuh), or H-PLOC (faster, trees that trace at
/// 0.85-0.99x of it, bvh_build.cuh).
enum class GpuBuildAlgorithm { kBinnedSah, kHploc };

struct GpuBvhBuildOptions {
    GpuBuildAlgorithm gpu_algorithm = GpuBuildAlgorithm::kBinnedSah;  // GpuBvhBuilder only
    // Aila and Laine build with leaves of at most 8 triangles and equal node and triangle
    // costs; 4 keeps the divergent leaf loop short on wide warps.
    int max_leaf_size = 4;
    int bins = 32;
    float traversal_cost = 1.0f;
    float intersection_cost = 1.0f;
    // The host build (build_gpu_triangle_bvh) only: split space too where a node's two
    // object-split boxes overlap (Stich et al. 2009), as TriangleAccel does, so a triangle
    // may sit in several leaves. Sponza's rays trace 1.1-1.3x faster on an H100
    // (docs/performance.md). Off where an any-hit program must see each triangle once per
    // ray. The GPU algorithms split objects only.
    bool spatial_splits = true;
};

struct GpuBvhStats {
    const char* builder = "binned SAH (host)";
    double build_ms = 0;    // binned-SAH build (lucent::accel::Bvh), or the GPU build kernels
    double convert_ms = 0;  // conversion to the GPU layout
    double sah_cost = 0;
    size_t node_count = 0;  // inner nodes of the GPU layout
    size_t leaf_count = 0;
    unsigned depth = 0;
};

/// The GPU layout in host memory (see triangle_bvh.cuh for the format).
struct GpuTriangleBvh {
    std::vector<float4> nodes;           // 4 per inner node, root first
    std::vector<float4> triangles;       // 3 per triangle, leaf order
    std::vector<uint32_t> triangle_ids;  // leaf order -> input order
    std::vector<uint32_t> parents;  // per node: parent << 1 | slot (~0u at the root), for refit
    GpuBvhStats stats;

    /// A view over these host arrays: lets the host run the GPU traversal (tests).
    gpu::GpuTriangleBvhView host_view() const {
        return {nodes.data(), triangles.data(), triangle_ids.data()};
    }
};

/// Builds over triangles (indices may be empty: then triangle i is vertices 3i..3i+2).
/// Throws lucent::Error for an index out of range or a mesh too big for the format.
GpuTriangleBvh build_gpu_triangle_bvh(std::span<const float3> positions,
                                      std::span<const uint3> indices,
                                      const GpuBvhBuildOptions& options = {});

/// The triangles a layout without spatial splits was built from, in input order and
/// unindexed (triangle i is vertices 3i .. 3i + 2): `triangles` and `triangle_ids` as a
/// GpuTriangleBvh holds them. Throws lucent::Error when the ids are not each input triangle
/// once (a layout with spatial splits, or a corrupt one).
std::vector<float3> layout_input_triangles(std::span<const float4> triangles,
                                           std::span<const uint32_t> triangle_ids);

/// A GpuTriangleBvh in device memory.
struct GpuTriangleBvhDevice {
    DeviceBuffer nodes, triangles, triangle_ids, parents;
    size_t node_count = 0, triangle_count = 0;  // in use (the buffers may be larger)
    /// Device pointers, to pass to kernels by value.
    gpu::GpuTriangleBvhView view() const {
        return {nodes.as<float4>(), triangles.as<float4>(), triangle_ids.as<unsigned>()};
    }
};

/// Uploads (synchronously) into `device`, reusing its buffers when the sizes match.
void upload_gpu_triangle_bvh(const GpuTriangleBvh& bvh, GpuTriangleBvhDevice& device);

}  // namespace lucent::cuda

// Gathers a GeometryGroup's triangles on the GPU: the vertex and index buffers of each of its
// instances, already mirrored in device memory, become one mesh (vertices concatenated,
// indices rebased onto them) for the BVH builder, so the host neither gathers nor uploads
// them (the host's form of the same mesh: src/core/triangle_gather.cpp). One thread per
// vertex and per triangle; each finds its instance ("piece") by a binary search over the
// pieces' first elements. Launched by src/cuda/accel/gpu_bvh_builder.cpp; the per-element
// functions also run on the CPU in tests/gpu_bvh_builder_test.cpp.
#pragma once

#include "lucent/device/platform.h"
#include "lucent/device/types.h"

namespace lucent::gpu {

/// One instance's triangles in device memory, and where they go in the gathered mesh.
struct GpuTrianglePiece {
    const float3* positions;
    const uint3* indices;                     // null: triangle i is positions[3i .. 3i + 2]
    unsigned vertex_first, vertex_count;      // in the gathered vertices
    unsigned triangle_first, triangle_count;  // in the gathered triangles
};

struct GpuGatherParams {
    const GpuTrianglePiece* pieces;
    unsigned piece_count;
    unsigned vertex_total, triangle_total;
    float3* positions;  // vertex_total
    uint3* indices;     // triangle_total
};

/// The last piece whose first element (vertex_first or triangle_first) is at most `index`.
template <bool kVertices>
LUCENT_HD inline unsigned gather_piece_of(const GpuGatherParams& p, unsigned index) {
    unsigned lo = 0, hi = p.piece_count;  // the answer is in [lo, hi)
    while (hi - lo > 1) {
        const unsigned mid = (lo + hi) / 2;
        const unsigned first =
            kVertices ? p.pieces[mid].vertex_first : p.pieces[mid].triangle_first;
        if (first <= index)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/// Element `i` of the gathered mesh: vertex i (i < vertex_total) and triangle i (i <
/// triangle_total), its indices moved by its piece's first vertex.
LUCENT_HD inline void gather_element(const GpuGatherParams& p, unsigned i) {
    if (i < p.vertex_total) {
        const GpuTrianglePiece& piece = p.pieces[gather_piece_of<true>(p, i)];
        p.positions[i] = piece.positions[i - piece.vertex_first];
    }
    if (i < p.triangle_total) {
        const GpuTrianglePiece& piece = p.pieces[gather_piece_of<false>(p, i)];
        const unsigned local = i - piece.triangle_first;
        const uint3 t = piece.indices ? piece.indices[local]
                                      : make_uint3(3 * local, 3 * local + 1, 3 * local + 2);
        const unsigned base = piece.vertex_first;
        p.indices[i] = make_uint3(t.x + base, t.y + base, t.z + base);
    }
}

}  // namespace lucent::gpu

#if LUCENT_GPU_CODE
extern "C" __global__ void lucent_gather_triangles(lucent::gpu::GpuGatherParams p) {
    lucent::gpu::gather_element(p, blockIdx.x * blockDim.x + threadIdx.x);
}
#endif

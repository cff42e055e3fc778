// The layout TriangleAccel traverses: 8-wide nodes with SoA child boxes, and leaves of
// up to four triangles stored SoA for the watertight test, four lanes at once.
#pragma once

#include <cstdint>
#include <vector>

#include "accel/bvh.h"
#include "accel/huge_page_allocator.h"

namespace lucent::accel {

constexpr int kWideArity = 8;
constexpr uint32_t kEmptyChild = 0xffffffffu;
constexpr uint32_t kLeafBit = 0x80000000u;
constexpr int kLeafCountShift = 29;  // bits 29..30 hold the leaf's triangle count - 1
constexpr uint32_t kLeafIndexMask = (1u << kLeafCountShift) - 1;

/// One node: box planes [axis][lo, hi][child], then child references. A reference is a
/// node index, or kLeafBit | (count - 1) << kLeafCountShift | block index, or kEmptyChild.
/// An empty slot has an inverted box (lo = +inf, hi = -inf) so it never hits.
struct alignas(64) WideNode {
    float planes[3][2][kWideArity];
    uint32_t child[kWideArity];
};

/// Four triangles: vertex[v][axis][lane], then the input index of each lane.
struct alignas(64) TriangleBlock {
    float vertex[3][3][4];
    uint32_t prim[4];
};

using WideNodes = std::vector<WideNode, HugePageAllocator<WideNode>>;
using TriangleBlocks = std::vector<TriangleBlock, HugePageAllocator<TriangleBlock>>;

inline bool is_leaf(uint32_t ref) {
    return (ref & kLeafBit) != 0;
}
inline uint32_t leaf_block(uint32_t ref) {
    return ref & kLeafIndexMask;
}
inline uint32_t leaf_count(uint32_t ref) {
    return ((ref >> kLeafCountShift) & 3u) + 1;
}

struct TriangleAccel::Impl {
    Bvh binary;                   // the SAH tree, kept for refit
    WideNodes nodes;  // nodes[0] is the root
    TriangleBlocks blocks;
    size_t triangle_count = 0;
    unsigned wide_depth = 0;
    double sah_cost = 0.0;

    /// Rebuilds nodes and blocks from `binary` and the current vertices.
    void collapse(std::span<const float3> vertices, std::span<const uint3> indices);
};

}  // namespace lucent::accel

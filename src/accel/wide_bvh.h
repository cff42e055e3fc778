// The layout TriangleAccel traverses: 8-wide nodes with SoA child boxes, and leaves of up
// to eight triangles stored SoA for the watertight test, four or eight lanes at once.
#pragma once

#include <cstdint>
#include <vector>

#include "accel/bvh.h"
#include "accel/huge_page_allocator.h"
#include "accel/wide_collapse.h"  // kWideArity

namespace lucent::accel {

constexpr uint32_t kEmptyChild = 0xffffffffu;
constexpr uint32_t kLeafBit = 0x80000000u;
constexpr int kLeafCountShift = 28;  // bits 28..30 hold the leaf's triangle count - 1
constexpr uint32_t kLeafIndexMask = (1u << kLeafCountShift) - 1;
constexpr uint32_t kMaxLeafTriangles = 8;
constexpr uint32_t kNarrowLeafTriangles = 4;  // leaves up to this size use 4-lane blocks

/// One node: box planes [axis][lo, hi][child], then child references. A reference is a
/// node index, or kLeafBit | (count - 1) << kLeafCountShift | block index, or kEmptyChild.
/// An empty slot has an inverted box (lo = +inf, hi = -inf) so it never hits.
struct alignas(64) WideNode {
    float planes[3][2][kWideArity];
    uint32_t child[kWideArity];
};

/// The triangles of one leaf, tested in one SIMD step: vertex[v][axis][lane], then the
/// input index of each lane. A leaf of up to four triangles is a 4-lane block (three cache
/// lines), a larger one an 8-lane block (five): with 256-bit registers the 8-wide test
/// costs the same instructions as the 4-wide one, one test where two blocks took two.
template <int kLanes>
struct alignas(64) TriangleBlock {
    float vertex[3][3][kLanes];
    uint32_t prim[kLanes];
};
using TriangleBlock4 = TriangleBlock<4>;
using TriangleBlock8 = TriangleBlock<8>;

using WideNodes = std::vector<WideNode, HugePageAllocator<WideNode>>;
template <int kLanes>
using TriangleBlocks = std::vector<TriangleBlock<kLanes>, HugePageAllocator<TriangleBlock<kLanes>>>;

inline bool is_leaf(uint32_t ref) {
    return (ref & kLeafBit) != 0;
}
/// The block's index in TriangleAccel::Impl::blocks4, or blocks8 for a wide leaf.
inline uint32_t leaf_block(uint32_t ref) {
    return ref & kLeafIndexMask;
}
inline uint32_t leaf_count(uint32_t ref) {
    return ((ref >> kLeafCountShift) & 7u) + 1;
}
inline bool is_wide_leaf(uint32_t ref) {
    return leaf_count(ref) > kNarrowLeafTriangles;
}

struct TriangleAccel::Impl {
    Bvh binary;                 // the SAH tree, kept for refit
    WideNodes nodes;            // nodes[0] is the root
    TriangleBlocks<4> blocks4;  // leaves of 1 to 4 triangles
    TriangleBlocks<8> blocks8;  // leaves of 5 to 8 triangles
    size_t triangle_count = 0;
    unsigned wide_depth = 0;
    double sah_cost = 0.0;

    /// Rebuilds nodes and blocks from `binary` and the current vertices.
    void collapse(std::span<const float3> vertices, std::span<const uint3> indices);
};

}  // namespace lucent::accel

// Which nodes of a binary BVH become the children of each 8-wide node: the optimal collapse
// of Ylitie, Karras and Laine 2017 ("Efficient incoherent ray traversal on GPUs through
// compressed wide BVHs", Sec. 3.1), without its leaf formation: the binary leaves stay the
// leaves. TriangleAccel's CPU layout (wide_bvh.h).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "accel/bvh.h"

namespace lucent::accel {

constexpr int kWideArity = 8;

class WideCollapse {
  public:
    /// Plans over `binary` (not empty) by dynamic programming, bottom-up: cover[n][k] is the
    /// least SAH cost of standing in for binary node n with at most k subtrees, each a leaf
    /// or a wide node. A wide node costs its area, a leaf leaf_cost(count) times its area.
    template <class LeafCost>
    WideCollapse(const Bvh& binary, LeafCost&& leaf_cost) : m_binary(binary) {
        const auto& bn = binary.nodes();
        m_leaf_cost.resize(bn.size());
        for (size_t i = 0; i < bn.size(); ++i)
            if (bn[i].count > 0) m_leaf_cost[i] = float(leaf_cost(bn[i].count));
        plan();
    }

    /// The binary nodes standing in for binary node n as the children of one wide node:
    /// n itself when it is a leaf (a tree of one leaf), else up to kWideArity subtrees of
    /// its two children. Returns how many were written to `kids`.
    int children(uint32_t n, uint32_t (&kids)[kWideArity]) const;

    /// children(n), placed in the slots of a wide node by position (Sec. 3.2 of the paper):
    /// slot s wants the child nearest the corner of n's box that is high on the axes of the
    /// bits of s, so that a ray whose direction is negative on the axes of the bits of o
    /// meets the children about in the order s ^ o. Greedily, the best-aligned pair of a free
    /// child and a free slot first. slot_kid[s] is a binary node, or kNoChild.
    static constexpr uint32_t kNoChild = 0xffffffffu;
    void children_by_octant(uint32_t n, uint32_t (&slot_kid)[kWideArity]) const;

  private:
    void plan();
    float best_children(uint32_t n, int& left_share) const;
    void collect(uint32_t n, int k, uint32_t* kids, int& count) const;

    const Bvh& m_binary;
    std::vector<float> m_leaf_cost;  // per binary leaf, per unit area
    // cover[n][k], k = 1..kWideArity; split[n][k]: subtrees given to n's first child, or 0
    // when n stands as one subtree itself.
    std::vector<std::array<float, kWideArity + 1>> m_cover;
    std::vector<std::array<uint8_t, kWideArity + 1>> m_split;
};

}  // namespace lucent::accel

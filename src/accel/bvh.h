// Binary BVH over arbitrary boxes, built with binned SAH (Wald 2007), with refit and a
// generic front-to-back traversal that hands leaf primitives to a callback.
// Used by the engine for Groups (children) and GeometryGroups with custom primitives.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lucent/device/types.h"

namespace lucent::accel {

struct BuildOptions {
    int bins = 32;  // SAH bins per axis
    // Primitives per leaf at most; 0 takes the structure's own: 4 for a Bvh, 8 for a
    // TriangleAccel (one 8-lane block).
    int max_leaf_size = 0;
    float traversal_cost = 1.0f;
    float intersection_cost = 1.0f;
    // TriangleAccel: split space too, not only the triangles (see SplitTriangles). Off where
    // an any-hit program must see each triangle once per ray.
    bool spatial_splits = true;
    // Threads the build may use (0: one per core). `lucent bench build --threads N` gives
    // Lucent's build the threads it gives Embree's.
    unsigned threads = 0;
};

/// Triangles behind the boxes of a build, for spatial splits (Stich, Friedrich and Dietrich
/// 2009, "Spatial splits in bounding volume hierarchies"): box i is triangle i (indices may
/// be empty: then triangle i is vertices 3i .. 3i + 2). A triangle may then sit in several
/// leaves, so a filtered traversal may offer it more than once.
struct SplitTriangles {
    std::span<const float3> vertices;
    std::span<const uint3> indices;
    float budget = 0.25f;  // at most this many references more than triangles, per triangle
};

struct BuildStats {
    double build_ms = 0;  // wall time of the build
    double sah_cost = 0;  // SAH cost of the tree (traversal_cost, intersection_cost above)
    size_t node_count = 0;
    size_t leaf_count = 0;
    size_t large_leaf_count = 0;  // TriangleAccel: leaves of 5 to 8 triangles (8-lane blocks)
    unsigned depth = 0;
};

/// A node of the binary BVH: a box, and either two children (count == 0, children at
/// first and first + 1) or `count` primitives at prim_order()[first ...].
struct BvhNode {
    float3 lo;
    uint32_t first;
    float3 hi;
    uint32_t count;
};

class Bvh {
  public:
    /// Builds over one box per primitive. Empty input gives an empty tree. With `split`,
    /// the boxes are triangles' and nodes may also split space, duplicating references.
    void build(std::span<const Aabb> boxes, const BuildOptions& options = {},
               BuildStats* stats = nullptr, const SplitTriangles* split = nullptr);
    /// Recomputes node boxes bottom-up for moved primitives (same count, same order).
    void refit(std::span<const Aabb> boxes);

    bool empty() const { return m_nodes.empty(); }
    Aabb bounds() const;
    const std::vector<BvhNode>& nodes() const { return m_nodes; }
    const std::vector<uint32_t>& prim_order() const { return m_prim_order; }
    /// SAH cost of the current tree.
    double sah_cost(const BuildOptions& options = {}) const;

    /// Calls visit(prim) -> bool(stop) for every primitive of every leaf whose box the ray
    /// overlaps within [tmin, tmax], nearer children first. `tmax` is read at each step, so
    /// the callback may shorten it (by writing to the variable passed in) to cull farther nodes.
    template <class Visit>
    void traverse(float3 origin, float3 direction, float tmin, const float& tmax,
                  Visit&& visit) const;

  private:
    friend class TriangleAccel;  // sets m_block_size for its four-wide leaves

    std::vector<BvhNode> m_nodes;
    // Primitives tested together in one SIMD step: the SAH counts leaf work in blocks of
    // this size, as Embree's builders do for Triangle4 leaves.
    unsigned m_block_size = 1;
    std::vector<uint32_t> m_prim_order;
};

}  // namespace lucent::accel

#include "accel/bvh_traverse.inl"

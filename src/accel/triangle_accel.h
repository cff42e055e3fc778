// Acceleration structure for triangle meshes: binned-SAH build, a layout tuned for
// single-ray CPU traversal, the built-in watertight ray/triangle test (Woop, Benthin and
// Wald 2013), closest-hit, any-hit (occlusion) and filtered queries, and refit.
// Used by GeometryGroups made only of GeometryTriangles, and by `lucent bench rays`.
#pragma once

#include <memory>
#include <span>

#include "accel/bvh.h"
#include "accel/ray_stream.h"

namespace lucent::accel {

struct TriangleHit {
    float t;
    float u, v;     // barycentrics of vertices 1 and 2 (adjacent: read as one float2)
    uint32_t prim;  // triangle index in the input order
    // Its vertices in the leaf the traversal tested, for hit_vertices():
    // vertex_lane[(3 * k + axis) * lanes] is coordinate `axis` of vertex k.
    const float* vertex_lane = nullptr;
    uint32_t lanes = 0;
};

/// The vertices of a hit's triangle (as given to build or refit, in its index order), read
/// from the leaf the traversal just tested: in cache, where the mesh's own arrays may not
/// be. Inline, so they go to registers: copied out through memory they were stored in
/// pieces and reloaded whole, a store-forwarding stall.
inline void hit_vertices(const TriangleHit& hit, float3& p0, float3& p1, float3& p2) {
    const float* v = hit.vertex_lane;
    const uint32_t n = hit.lanes;
    p0 = make_float3(v[0], v[n], v[2 * n]);
    p1 = make_float3(v[3 * n], v[4 * n], v[5 * n]);
    p2 = make_float3(v[6 * n], v[7 * n], v[8 * n]);
}

/// What a filter (the engine's any-hit) decides about a candidate hit.
enum class HitDecision { kAccept, kIgnore, kAcceptAndStop };

class TriangleAccel {
  public:
    TriangleAccel();
    ~TriangleAccel();
    TriangleAccel(TriangleAccel&&) noexcept;
    TriangleAccel& operator=(TriangleAccel&&) noexcept;

    /// Builds over triangles (indices may be empty: then triangle i is vertices 3i..3i+2).
    void build(std::span<const float3> vertices, std::span<const uint3> indices,
               const BuildOptions& options = {}, BuildStats* stats = nullptr);
    /// Refit after vertices moved (same triangles).
    void refit(std::span<const float3> vertices, std::span<const uint3> indices);

    size_t triangle_count() const;
    Aabb bounds() const;
    double sah_cost() const;

    /// Closest hit with t in (tmin, tmax); false when there is none.
    bool intersect(float3 origin, float3 direction, float tmin, float tmax, TriangleHit& hit) const;
    /// True when any triangle is hit with t in (tmin, tmax).
    bool occluded(float3 origin, float3 direction, float tmin, float tmax) const;
    /// Conservative occlusion by the tree's leaf boxes (the IGI paper's imperfect
    /// visibility, §4.1, with a leaf's box for the triangles' boxes): true when the ray
    /// passes wholly through a leaf's box within (tmin, tmax), entering after tmin and
    /// leaving before tmax. A leaf box that holds either end does not count, or a surface
    /// would shadow itself. Triangles are never tested: inner nodes only.
    bool occluded_leaf_boxes(float3 origin, float3 direction, float tmin, float tmax) const;
    /// Closest hits of many rays traced together as ray streams (ray_stream.h): hits[i] is
    /// intersect()'s answer for rays[i] (only a tie between two triangles at the same t
    /// may name the other one). For many incoherent rays at once, such as a wavefront of
    /// diffuse bounces. Throws lucent::Error when the spans' sizes differ.
    void intersect_stream(std::span<const StreamRay> rays, std::span<StreamHit> hits,
                          RayStreamWorkspace& workspace) const;
    /// occluded() for many rays at once: blocked[i] is 1 when rays[i] is blocked, else 0.
    void occluded_stream(std::span<const StreamRay> rays, std::span<uint8_t> blocked,
                         RayStreamWorkspace& workspace) const;
    /// The boxes of the tree's leaves (for tests of occluded_leaf_boxes).
    std::vector<Aabb> leaf_boxes() const;

    /// Closest hit where every candidate nearer than the current closest is first offered
    /// to filter(const TriangleHit&) -> HitDecision. Candidates may come out of order.
    /// Returns true when a hit was accepted; `hit` holds the closest accepted one.
    template <class Filter>
    bool intersect_filtered(float3 origin, float3 direction, float tmin, float tmax,
                            TriangleHit& hit, Filter&& filter) const;

    struct Impl;

  private:
    using FilterThunk = HitDecision (*)(void* filter, const TriangleHit& candidate);
    bool intersect_filtered_impl(float3 origin, float3 direction, float tmin, float tmax,
                                 TriangleHit& hit, FilterThunk thunk, void* filter) const;

    std::unique_ptr<Impl> m_impl;
};

}  // namespace lucent::accel

#include "accel/triangle_accel_filtered.inl"

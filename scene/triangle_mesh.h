// Ray queries against a triangle mesh, batch in and answers out, without writing programs:
// the closest hit along each ray (t, triangle, barycentrics, normal) and whether anything lies
// on each ray (shadow rays, line of sight). Python's lucent.TriangleMesh is this class.
//
// On the CPU backend the queries go straight to the triangle BVH the engine builds for a
// GeometryGroup of triangles, traced as ray streams on all cores (mesh_queries/
// cpu_mesh_queries.h). On the GPU, and on the CPU when a JIT check or a device list is asked
// for, they run through a Context like any program: one GeometryTriangles under a
// GeometryGroup and the mesh_queries/mesh_query_programs.h module. Both give the same answers
// (a tie, two triangles at exactly the same t, may name the other one).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "lucent/context.h"

namespace lucent::scene {

/// A batch of rays. origins and directions hold one entry per ray (directions need not be
/// unit: t is in units of the direction's length). tmin and tmax hold one value for every
/// ray or one per ray; left empty, tmin is 0 and tmax has no bound. A ray with a NaN or
/// infinite origin or direction component, a zero direction or a NaN bound is a miss by
/// definition (it is not traced).
struct MeshRays {
    std::span<const float3> origins;
    std::span<const float3> directions;
    std::span<const float> tmin;
    std::span<const float> tmax;
};

/// Where TriangleMesh::intersect writes: each span one entry per ray.
struct MeshHits {
    std::span<float> t;        // +inf on a miss
    std::span<int32_t> prim;   // the triangle's index; -1 on a miss
    std::span<float2> uv;      // barycentrics of vertices 1 and 2; 0 on a miss
    std::span<float3> normal;  // unit geometric normal, in the winding order; 0 on a miss
};

/// A mesh's positions and triangles.
struct MeshTriangles {
    std::vector<float3> positions;
    std::vector<uint3> indices;
};

/// .obj through the OBJ mesh loader (positions and faces, as `lucent bench rays` reads
/// them); any other file (.json, .gltf, .glb, .ply) or built-in scene name ("cornell")
/// through the scene loader, its meshes placed where the scene draws them and joined. Throws
/// lucent::Error naming the file.
MeshTriangles load_mesh_triangles(const std::string& path);

/// Every call is serialised by the mesh's own mutex, so threads may share one.
class TriangleMesh {
  public:
    /// Copies the mesh. Every index must be below vertices.size() (lucent::Error naming the
    /// first triangle that is not). options picks the backend ("auto": the GPU if there is
    /// one), the CPU's threads, a JIT check. The BVH is built at the first query.
    TriangleMesh(std::span<const float3> vertices, std::span<const uint3> triangles,
                 ContextOptions options = {});
    /// load_mesh_triangles(path), then the constructor.
    static TriangleMesh load(const std::string& path, ContextOptions options = {});
    ~TriangleMesh();
    TriangleMesh(TriangleMesh&&) noexcept;
    TriangleMesh& operator=(TriangleMesh&&) noexcept;

    /// The closest hit along each ray in (tmin, tmax). Each of out's spans must have one entry
    /// per ray. lucent::Error naming the argument when a size does not fit.
    void intersect(const MeshRays& rays, const MeshHits& out);
    /// Whether any triangle lies on each ray in (tmin, tmax): 1 or 0 into `blocked`, one entry
    /// per ray. The shadow-ray query: it stops at the first triangle found.
    void occluded(const MeshRays& rays, std::span<uint8_t> blocked);

    /// New positions for the same vertex count: the BVH is refitted at the next query, or
    /// rebuilt when `rebuild` (better after large motions).
    void update(std::span<const float3> vertices, bool rebuild = false);

    size_t vertex_count() const;
    size_t triangle_count() const;
    /// The backend that answers: "cpu (2 threads)", "cuda (...)".
    std::string backend_name() const;
    /// The most recent query's launch report (accel_ms for a build or refit, launch_ms;
    /// jit_ms with a JIT check), a copy.
    LaunchReport last_launch() const;

  private:
    struct Impl;
    /// The state, or lucent::Error naming `where` on a moved-from mesh.
    Impl& impl(const char* where) const;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace lucent::scene

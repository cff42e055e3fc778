// The engine side of lucent.TriangleMesh, free of Python. On the CPU backend the queries
// call the triangle BVH directly (cpu_ray_queries.h). On the GPU, and on the CPU when a
// JIT check or a device list is asked for, they run through a Context: one
// GeometryTriangles under a GeometryGroup, the ray_query_programs.h module's two entry
// points, and the buffers the rays go in and the answers come out through. Both give the
// same answers. The binding (mesh_binding.cpp) checks the numpy arrays and calls this
// without the GIL.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "lucent/lucent.h"
#include "cpu_ray_queries.h"
#include "ray_query_arrays.h"

namespace lucent::python {

/// A mesh's positions and triangles as loaded from a file.
struct MeshData {
    std::vector<float3> positions;
    std::vector<uint3> indices;
};

/// .obj through the OBJ mesh loader (positions and faces, as `lucent bench rays` reads
/// them); any other file or built-in scene name through the scene loader, its meshes
/// concatenated. Throws lucent::Error naming the file.
MeshData load_mesh(const std::string& path);

/// Every call is serialised by the mesh's own mutex, so Python threads may share one.
class RayQueryMesh {
  public:
    /// vertices: vertex_count x 3 floats; indices: triangle_count x 3, each < vertex_count
    /// (the caller checks).
    RayQueryMesh(const float* vertices, size_t vertex_count, const uint32_t* indices,
                 size_t triangle_count, ContextOptions options);

    /// New positions for the same vertex count: the BVH is refitted at the next query,
    /// or rebuilt when `rebuild`.
    void update(const float* vertices, size_t vertex_count, bool rebuild);

    void intersect(const RayArrays& rays, const HitArrays& out);
    /// out: count bytes, 1 where something lies on the ray in (tmin, tmax).
    void occluded(const RayArrays& rays, uint8_t* out);

    size_t vertex_count() const { return m_vertex_count; }
    size_t triangle_count() const { return m_triangle_count; }
    std::string backend_name() const;
    /// The most recent query's launch report (timings, JIT), a copy.
    LaunchReport last_launch() const;

  private:
    /// The Context, its graph, programs and buffers (the GPU's path).
    void build_engine_queries(const float* vertices, const uint32_t* indices);
    /// Copies the rays into the input buffers, sizing every batch buffer to the batch.
    void load_rays(const RayArrays& rays);

    mutable std::mutex m_mutex;
    size_t m_vertex_count, m_triangle_count;
    std::string m_backend_name;
    std::unique_ptr<CpuRayQueries> m_cpu;  // the CPU's direct queries, or
    std::unique_ptr<Context> m_ctx;        // the engine's
    std::shared_ptr<Buffer> m_vertices;
    std::shared_ptr<Acceleration> m_accel;
    std::shared_ptr<Program> m_closest, m_any;
    // Rays in, answers out: sized for the last batch.
    size_t m_count = 0;
    std::shared_ptr<Buffer> m_origins, m_directions, m_tmin, m_tmax;
    std::shared_ptr<Buffer> m_t, m_prim, m_uv, m_normal, m_blocked;
};

}  // namespace lucent::python

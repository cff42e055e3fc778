// The CPU side of TriangleMesh (scene/triangle_mesh.h): the rays of a batch go straight to
// the triangle BVH the engine builds for a GeometryGroup of triangles (accel::TriangleAccel,
// the same build and the same watertight test), on a pool of worker threads, as ray streams
// (accel/ray_stream.h): each worker takes batches of the caller's rays and traces each
// batch node by node, then writes the answers into the caller's arrays. No programs around
// the traversal. The answers are those of the query module (mesh_query_programs.h) on the CPU
// backend, bit for bit: the same rules for what a ray is (ray_query_rules.h) and the same
// attribute formula (runtime::builtin_triangle_attributes). Only a tie, two triangles hit at
// exactly the same t, may name the other triangle, as the stream meets them in another order.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "accel/triangle_accel.h"
#include "cpu/thread_pool.h"
#include "lucent/context.h"
#include "scene/triangle_mesh.h"

namespace lucent::scene::detail {

class CpuMeshQueries {
  public:
    /// Indices each below vertices.size() (the caller checks). threads: workers counting the
    /// caller, 0 = one per core. The BVH is built at the first query, as the engine builds
    /// it at the first launch.
    CpuMeshQueries(std::span<const float3> vertices, std::span<const uint3> triangles,
                   unsigned threads);

    /// New positions (same count): the BVH is refitted at the next query, or rebuilt.
    void update(std::span<const float3> vertices, bool rebuild);

    /// Sizes checked by the caller (TriangleMesh), and tmin and tmax never empty: one value
    /// for every ray or one per ray.
    void intersect(const MeshRays& rays, const MeshHits& out);
    void occluded(const MeshRays& rays, std::span<uint8_t> out);

    unsigned threads() const { return m_pool.size(); }
    /// The last query's figures: accel_ms for a build or refit it made, launch_ms for the rays.
    const LaunchReport& last_launch() const { return m_report; }

  private:
    enum class BvhState { kCurrent, kBuild, kRefit };
    /// Builds or refits the BVH if the vertices changed; starts m_report.
    void prepare();
    /// What a worker keeps from query to query: its stream workspace and one batch's rays
    /// and answers.
    struct StreamWorker {
        accel::RayStreamWorkspace workspace;
        std::vector<accel::StreamRay> rays;
        std::vector<accel::StreamHit> hits;
    };
    /// Runs trace(begin, count, worker) over the rays [0, count) in batches taken by the
    /// workers, each batch's rays already in worker.rays (a ray that is not one, by
    /// ray_query_rules.h, made one that hits nothing).
    template <class Trace>
    void for_each_batch(const MeshRays& rays, const Trace& trace);

    std::vector<float3> m_vertices;
    std::vector<uint3> m_indices;
    accel::TriangleAccel m_accel;
    BvhState m_bvh = BvhState::kBuild;
    cpu::ThreadPool m_pool;
    std::vector<StreamWorker> m_workers;  // one per worker of m_pool
    LaunchReport m_report;
};

}  // namespace lucent::scene::detail

#include "scene/mesh_queries/cpu_mesh_queries.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>

#include "runtime/trace_rules.h"
#include "scene/mesh_queries/ray_query_rules.h"

namespace lucent::scene::detail {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// The ray of batch entry i, or false when it is not a ray (ray_query_rules.h). tmin and
/// tmax hold one value for every ray or one per ray, as the query module reads them.
bool batch_ray(const MeshRays& rays, size_t i, Ray& ray) {
    return lucent_mesh_queries::query_ray(rays.origins[i], rays.directions[i],
                                          rays.tmin[rays.tmin.size() == 1 ? 0 : i],
                                          rays.tmax[rays.tmax.size() == 1 ? 0 : i], ray);
}

}  // namespace

CpuMeshQueries::CpuMeshQueries(std::span<const float3> vertices, std::span<const uint3> triangles,
                               unsigned threads)
    : m_vertices(vertices.begin(), vertices.end()),
      m_indices(triangles.begin(), triangles.end()),
      m_pool(threads),
      m_workers(m_pool.size()) {}

void CpuMeshQueries::update(std::span<const float3> vertices, bool rebuild) {
    std::copy(vertices.begin(), vertices.end(), m_vertices.begin());
    // A refit keeps a BVH that was built: one not built yet is built from the new vertices.
    if (rebuild || m_bvh == BvhState::kBuild)
        m_bvh = BvhState::kBuild;
    else
        m_bvh = BvhState::kRefit;
}

void CpuMeshQueries::prepare() {
    m_report = LaunchReport{};
    if (m_bvh == BvhState::kCurrent) return;
    const auto start = Clock::now();
    // The engine's build for a GeometryGroup of triangles without any-hit programs
    // (core/accel_builder.cpp): the default options, spatial splits on.
    if (m_bvh == BvhState::kRefit)
        m_accel.refit(m_vertices, m_indices);
    else
        m_accel.build(m_vertices, m_indices, accel::BuildOptions{});
    m_bvh = BvhState::kCurrent;
    m_report.accel_ms = ms_since(start);
    m_report.recompiled = true;
}

template <class Trace>
void CpuMeshQueries::for_each_batch(const MeshRays& rays, const Trace& trace) {
    // Two batches a worker at least, so that the workers finish together, and no more than
    // a stream query takes at once. A batch of many rays is what makes streams pay: the
    // nodes near the leaves still see several rays each.
    const size_t count = rays.origins.size();
    const size_t workers = m_pool.size();
    const size_t batch =
        std::clamp<size_t>((count + 2 * workers - 1) / (2 * workers), 1024, accel::kStreamBatch);
    const size_t batches = (count + batch - 1) / batch;
    const bool no_triangles = m_indices.empty();
    std::atomic<size_t> next{0};
    const auto start = Clock::now();
    m_pool.run(
        [&](unsigned w) {
            StreamWorker& worker = m_workers[w];
            for (size_t b; (b = next.fetch_add(1, std::memory_order_relaxed)) < batches;) {
                const size_t begin = b * batch, n = std::min(count, begin + batch) - begin;
                worker.rays.resize(n);
                for (size_t k = 0; k < n; ++k) {
                    Ray ray;
                    if (!no_triangles && batch_ray(rays, begin + k, ray))
                        worker.rays[k] =
                            accel::StreamRay{ray.origin, ray.tmin, ray.direction, ray.tmax};
                    else  // an empty interval: no node or triangle passes it
                        worker.rays[k] = accel::StreamRay{make_float3(0, 0, 0), kInfinity,
                                                          make_float3(0, 0, 1), -kInfinity};
                }
                trace(begin, n, worker);
            }
        },
        unsigned(std::min<size_t>(batches, ~0u)));  // no more workers than batches
    m_report.launch_ms = ms_since(start);
}

void CpuMeshQueries::intersect(const MeshRays& rays, const MeshHits& out) {
    prepare();
    for_each_batch(rays, [&](size_t begin, size_t n, StreamWorker& worker) {
        worker.hits.resize(n);
        m_accel.intersect_stream(worker.rays, worker.hits, worker.workspace);
        for (size_t k = 0; k < n; ++k) {
            // What the query module's closest_hits, record_hit and record_miss write.
            const accel::StreamHit& hit = worker.hits[k];
            const size_t i = begin + k;
            float t = lucent_mesh_queries::positive_infinity();
            int32_t prim = -1;
            runtime::AttributeBytes<sizeof(TriangleAttributes)> attr{};
            if (hit.prim != accel::kStreamMiss) {
                t = hit.t;
                prim = int32_t(hit.prim);
                // The vertices the BVH was built or refitted with, as the leaf holds them.
                const uint3 tri = m_indices[hit.prim];
                runtime::builtin_triangle_attributes(make_float2(hit.u, hit.v), m_vertices[tri.x],
                                                     m_vertices[tri.y], m_vertices[tri.z], attr);
            }
            out.t[i] = t;
            out.prim[i] = prim;
            std::memcpy(&out.uv[i], attr.bytes + offsetof(TriangleAttributes, barycentrics),
                        sizeof(float2));
            std::memcpy(&out.normal[i], attr.bytes + offsetof(TriangleAttributes, geometric_normal),
                        sizeof(float3));
        }
    });
}

void CpuMeshQueries::occluded(const MeshRays& rays, std::span<uint8_t> out) {
    prepare();
    for_each_batch(rays, [&](size_t begin, size_t n, StreamWorker& worker) {
        m_accel.occluded_stream(worker.rays, out.subspan(begin, n), worker.workspace);
    });
}

}  // namespace lucent::scene::detail

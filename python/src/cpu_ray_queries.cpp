#include "cpu_ray_queries.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>

#include "ray_query_rules.h"
#include "runtime/trace_rules.h"

namespace lucent::python {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

float3 element3(const float* values, size_t i) {
    return make_float3(values[3 * i], values[3 * i + 1], values[3 * i + 2]);
}

/// The ray of batch entry i, or false when it is not a ray (ray_query_rules.h).
bool batch_ray(const RayArrays& rays, size_t i, Ray& ray) {
    return lucent_python::query_ray(element3(rays.origins, i), element3(rays.directions, i),
                                    rays.tmin[rays.tmin_count == 1 ? 0 : i],
                                    rays.tmax[rays.tmax_count == 1 ? 0 : i], ray);
}

}  // namespace

CpuRayQueries::CpuRayQueries(const float* vertices, size_t vertex_count, const uint32_t* indices,
                             size_t triangle_count, unsigned threads)
    : m_vertices(reinterpret_cast<const float3*>(vertices),
                 reinterpret_cast<const float3*>(vertices) + vertex_count),
      m_indices(reinterpret_cast<const uint3*>(indices),
                reinterpret_cast<const uint3*>(indices) + triangle_count),
      m_pool(threads),
      m_workers(m_pool.size()) {}

void CpuRayQueries::update(const float* vertices, bool rebuild) {
    std::memcpy(m_vertices.data(), vertices, m_vertices.size() * sizeof(float3));
    // A refit keeps a BVH that was built: one not built yet is built from the new vertices.
    if (rebuild || m_bvh == BvhState::kBuild)
        m_bvh = BvhState::kBuild;
    else
        m_bvh = BvhState::kRefit;
}

void CpuRayQueries::prepare() {
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
void CpuRayQueries::for_each_batch(const RayArrays& rays, const Trace& trace) {
    // Two batches a worker at least, so that the workers finish together, and no more than
    // a stream query takes at once. A batch of many rays is what makes streams pay: the
    // nodes near the leaves still see several rays each.
    const size_t count = rays.count;
    const size_t workers = m_pool.size();
    const size_t batch = std::clamp<size_t>((count + 2 * workers - 1) / (2 * workers), 1024,
                                            accel::kStreamBatch);
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
                        worker.rays[k] = accel::StreamRay{ray.origin, ray.tmin, ray.direction,
                                                          ray.tmax};
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

void CpuRayQueries::intersect(const RayArrays& rays, const HitArrays& out) {
    prepare();
    for_each_batch(rays, [&](size_t begin, size_t n, StreamWorker& worker) {
        worker.hits.resize(n);
        m_accel.intersect_stream(worker.rays, worker.hits, worker.workspace);
        for (size_t k = 0; k < n; ++k) {
            // What the query module's closest_hits, record_hit and record_miss write.
            const accel::StreamHit& hit = worker.hits[k];
            const size_t i = begin + k;
            float t = lucent_python::positive_infinity();
            int32_t prim = -1;
            runtime::AttributeBytes<sizeof(TriangleAttributes)> attr{};
            if (hit.prim != accel::kStreamMiss) {
                t = hit.t;
                prim = int32_t(hit.prim);
                // The vertices the BVH was built or refitted with, as the leaf holds them.
                const uint3 tri = m_indices[hit.prim];
                runtime::builtin_triangle_attributes(make_float2(hit.u, hit.v),
                                                     m_vertices[tri.x], m_vertices[tri.y],
                                                     m_vertices[tri.z], attr);
            }
            out.t[i] = t;
            out.prim[i] = prim;
            std::memcpy(out.uv + 2 * i, attr.bytes + offsetof(TriangleAttributes, barycentrics),
                        2 * sizeof(float));
            std::memcpy(out.normal + 3 * i,
                        attr.bytes + offsetof(TriangleAttributes, geometric_normal),
                        3 * sizeof(float));
        }
    });
}

void CpuRayQueries::occluded(const RayArrays& rays, uint8_t* out) {
    prepare();
    for_each_batch(rays, [&](size_t begin, size_t n, StreamWorker& worker) {
        m_accel.occluded_stream(worker.rays, std::span<uint8_t>(out + begin, n), worker.workspace);
    });
}

}  // namespace lucent::python

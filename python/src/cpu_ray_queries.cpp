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
      m_pool(threads) {}

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

template <class Answer>
void CpuRayQueries::for_each_ray(size_t count, const Answer& answer) {
    // Chunks as small as the CPU backend's 1D tiles keep both workers busy to the end.
    constexpr size_t kChunk = 64;
    const size_t chunks = (count + kChunk - 1) / kChunk;
    std::atomic<size_t> next{0};
    const auto start = Clock::now();
    m_pool.run(
        [&](unsigned) {
            for (size_t c; (c = next.fetch_add(1, std::memory_order_relaxed)) < chunks;) {
                const size_t end = std::min(count, (c + 1) * kChunk);
                for (size_t i = c * kChunk; i < end; ++i) answer(i);
            }
        },
        unsigned(std::min<size_t>(chunks, ~0u)));  // no more workers than chunks
    m_report.launch_ms = ms_since(start);
}

void CpuRayQueries::intersect(const RayArrays& rays, const HitArrays& out) {
    prepare();
    const bool no_triangles = m_indices.empty();
    for_each_ray(rays.count, [&](size_t i) {
        // What the query module's closest_hits, record_hit and record_miss write.
        float t = lucent_python::positive_infinity();
        int32_t prim = -1;
        runtime::AttributeBytes<sizeof(TriangleAttributes)> attr{};
        Ray ray;
        accel::TriangleHit hit;
        if (!no_triangles && batch_ray(rays, i, ray) &&
            m_accel.intersect(ray.origin, ray.direction, ray.tmin, ray.tmax, hit)) {
            t = hit.t;
            prim = int32_t(hit.prim);
            float3 p0, p1, p2;
            accel::hit_vertices(hit, p0, p1, p2);
            runtime::builtin_triangle_attributes(make_float2(hit.u, hit.v), p0, p1, p2, attr);
        }
        out.t[i] = t;
        out.prim[i] = prim;
        std::memcpy(out.uv + 2 * i, attr.bytes + offsetof(TriangleAttributes, barycentrics),
                    2 * sizeof(float));
        std::memcpy(out.normal + 3 * i,
                    attr.bytes + offsetof(TriangleAttributes, geometric_normal),
                    3 * sizeof(float));
    });
}

void CpuRayQueries::occluded(const RayArrays& rays, uint8_t* out) {
    prepare();
    const bool no_triangles = m_indices.empty();
    for_each_ray(rays.count, [&](size_t i) {
        Ray ray;
        out[i] = !no_triangles && batch_ray(rays, i, ray) &&
                 m_accel.occluded(ray.origin, ray.direction, ray.tmin, ray.tmax);
    });
}

}  // namespace lucent::python

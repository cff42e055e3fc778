// TriangleAccel's queries, routed to the traversal variant this CPU runs (cpu_isa.h).
// intersect_filtered arrives here with its filter already type-erased
// (triangle_accel_filtered.inl), so any-hit queries get the SIMD variants too.
//
// A query costs one load and one indirect jump more than a direct call: `g_active` starts
// at kResolve, whose functions pick the variant at the first query, store it and forward.
// A function-local static instead put a guard check on every query, and around its
// initializing call GCC saved and restored all the query's arguments each time.
#include <algorithm>
#include <atomic>
#include <string>

#include "accel/cpu_isa.h"
#include "accel/triangle_accel.h"
#include "accel/triangle_traverse.h"
#include "accel/wide_bvh.h"
#include "lucent/error.h"

namespace lucent::accel {

namespace {

extern const TraverseVariant kResolve;
// Constant-initialized, so a query from a static constructor finds it set; relaxed loads
// are enough, as it only ever points to constant-initialized tables.
constinit std::atomic<const TraverseVariant*> g_active{&kResolve};

const TraverseVariant& resolve() {
    const TraverseVariant& variant = traverse_variant(active_cpu_isa());
    g_active.store(&variant, std::memory_order_relaxed);
    return variant;
}

bool resolve_intersect(const TriangleAccel::Impl& accel, float3 origin, float3 direction,
                       float tmin, float tmax, TriangleHit& hit) {
    return resolve().intersect(accel, origin, direction, tmin, tmax, hit);
}
bool resolve_occluded(const TriangleAccel::Impl& accel, float3 origin, float3 direction, float tmin,
                      float tmax) {
    return resolve().occluded(accel, origin, direction, tmin, tmax);
}
bool resolve_occluded_leaf_boxes(const TriangleAccel::Impl& accel, float3 origin,
                                 float3 direction, float tmin, float tmax) {
    return resolve().occluded_leaf_boxes(accel, origin, direction, tmin, tmax);
}
bool resolve_filtered(const TriangleAccel::Impl& accel, float3 origin, float3 direction, float tmin,
                      float tmax, TriangleHit& hit, FilterThunk thunk, void* filter) {
    return resolve().intersect_filtered(accel, origin, direction, tmin, tmax, hit, thunk, filter);
}

void resolve_intersect_stream(const TriangleAccel::Impl& accel, const StreamRay* rays, size_t count,
                              StreamHit* hits, StreamBuffers& buffers) {
    resolve().intersect_stream(accel, rays, count, hits, buffers);
}
void resolve_occluded_stream(const TriangleAccel::Impl& accel, const StreamRay* rays, size_t count,
                             uint8_t* blocked, StreamBuffers& buffers) {
    resolve().occluded_stream(accel, rays, count, blocked, buffers);
}
constexpr TraverseVariant kResolve = {resolve_intersect,        resolve_occluded,
                                      resolve_occluded_leaf_boxes, resolve_filtered,
                                      resolve_intersect_stream, resolve_occluded_stream,
                                      "unresolved"};

const TraverseVariant& active() {
    return *g_active.load(std::memory_order_relaxed);
}

/// Hands trace(begin, count, buffers) the rays [0, total) in batches of at most
/// kStreamBatch, with the workspace's buffers reserved for each.
template <class Trace>
void for_each_stream_batch(size_t total, unsigned depth, RayStreamWorkspace& workspace,
                           const Trace& trace) {
    for (size_t begin = 0; begin < total; begin += kStreamBatch) {
        const size_t count = std::min(kStreamBatch, total - begin);
        trace(begin, count, workspace.reserve(count, depth));
    }
}

}  // namespace

bool TriangleAccel::intersect(float3 origin, float3 direction, float tmin, float tmax,
                              TriangleHit& hit) const {
    return active().intersect(*m_impl, origin, direction, tmin, tmax, hit);
}

bool TriangleAccel::occluded(float3 origin, float3 direction, float tmin, float tmax) const {
    return active().occluded(*m_impl, origin, direction, tmin, tmax);
}

bool TriangleAccel::occluded_leaf_boxes(float3 origin, float3 direction, float tmin,
                                        float tmax) const {
    return active().occluded_leaf_boxes(*m_impl, origin, direction, tmin, tmax);
}

bool TriangleAccel::intersect_filtered_impl(float3 origin, float3 direction, float tmin, float tmax,
                                            TriangleHit& hit, FilterThunk thunk,
                                            void* filter) const {
    return active().intersect_filtered(*m_impl, origin, direction, tmin, tmax, hit, thunk, filter);
}

void TriangleAccel::intersect_stream(std::span<const StreamRay> rays, std::span<StreamHit> hits,
                                     RayStreamWorkspace& workspace) const {
    if (hits.size() != rays.size())
        throw Error("TriangleAccel::intersect_stream: " + std::to_string(rays.size()) +
                    " rays but room for " + std::to_string(hits.size()) +
                    " hits; pass one StreamHit per ray");
    for_each_stream_batch(rays.size(), m_impl->wide_depth, workspace,
                          [&](size_t begin, size_t count, StreamBuffers& buffers) {
                              active().intersect_stream(*m_impl, rays.data() + begin, count,
                                                        hits.data() + begin, buffers);
                          });
}

void TriangleAccel::occluded_stream(std::span<const StreamRay> rays, std::span<uint8_t> blocked,
                                    RayStreamWorkspace& workspace) const {
    if (blocked.size() != rays.size())
        throw Error("TriangleAccel::occluded_stream: " + std::to_string(rays.size()) +
                    " rays but room for " + std::to_string(blocked.size()) +
                    " answers; pass one byte per ray");
    for_each_stream_batch(rays.size(), m_impl->wide_depth, workspace,
                          [&](size_t begin, size_t count, StreamBuffers& buffers) {
                              active().occluded_stream(*m_impl, rays.data() + begin, count,
                                                       blocked.data() + begin, buffers);
                          });
}

}  // namespace lucent::accel

// TriangleAccel's queries, routed to the traversal variant this CPU runs (cpu_isa.h).
// intersect_filtered arrives here with its filter already type-erased
// (triangle_accel_filtered.inl), so any-hit queries get the SIMD variants too.
//
// A query costs one load and one indirect jump more than a direct call: `g_active` starts
// at kResolve, whose functions pick the variant at the first query, store it and forward.
// A function-local static instead put a guard check on every query, and around its
// initializing call GCC saved and restored all the query's arguments each time.
#include <atomic>

#include "accel/cpu_isa.h"
#include "accel/triangle_accel.h"
#include "accel/triangle_traverse.h"

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

constexpr TraverseVariant kResolve = {resolve_intersect, resolve_occluded,
                                      resolve_occluded_leaf_boxes, resolve_filtered, "unresolved"};

const TraverseVariant& active() {
    return *g_active.load(std::memory_order_relaxed);
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

}  // namespace lucent::accel

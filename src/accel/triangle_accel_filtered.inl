// TriangleAccel::intersect_filtered (included from triangle_accel.h): the filter is
// type-erased into one function pointer so the traversal itself stays in a .cpp file, and
// so reaches the instruction-set variant this CPU runs (triangle_traverse_dispatch.cpp);
// the filter costs one indirect call per candidate hit, as it did before the dispatch.
#pragma once

#include <type_traits>

namespace lucent::accel {

template <class Filter>
bool TriangleAccel::intersect_filtered(float3 origin, float3 direction, float tmin, float tmax,
                                       TriangleHit& hit, Filter&& filter) const {
    using F = std::remove_reference_t<Filter>;
    FilterThunk thunk = [](void* f, const TriangleHit& candidate) -> HitDecision {
        return (*static_cast<F*>(f))(candidate);
    };
    return intersect_filtered_impl(origin, direction, tmin, tmax, hit, thunk,
                                   const_cast<void*>(static_cast<const void*>(&filter)));
}

}  // namespace lucent::accel

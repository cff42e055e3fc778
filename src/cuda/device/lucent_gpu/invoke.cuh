// Typed calls of program functions from type-erased pointers: the generated dispatch
// passes `&program`, and the template recovers the record, payload and attribute types
// from the function's own signature, so the generator never spells a type name.
#pragma once

#include "lucent/device.h"

namespace lucent::gpu {

template <class R>
__device__ __forceinline__ void invoke(void (*f)(const R&), const void* rec) {
    f(*static_cast<const R*>(rec));
}
template <class R>
__device__ __forceinline__ void invoke(void (*f)(const R&, const ExceptionInfo&), const void* rec,
                                       const ExceptionInfo& ex) {
    f(*static_cast<const R*>(rec), ex);
}
template <class R, class P>
__device__ __forceinline__ void invoke(void (*f)(const R&, P&), const void* rec, void* prd) {
    f(*static_cast<const R*>(rec), *static_cast<P*>(prd));
}
template <class R, class P, class A>
__device__ __forceinline__ void invoke(void (*f)(const R&, P&, const A&), const void* rec,
                                       void* prd, const void* attr) {
    f(*static_cast<const R*>(rec), *static_cast<P*>(prd), *static_cast<const A*>(attr));
}
// Any-hit programs: their hidden last parameter is what ignore_intersection() names.
template <class R, class P, class A>
__device__ __forceinline__ void invoke(void (*f)(const R&, P&, const A&, AnyHitScope),
                                       const void* rec, void* prd, const void* attr) {
    f(*static_cast<const R*>(rec), *static_cast<P*>(prd), *static_cast<const A*>(attr),
      AnyHitScope{});
}
template <class R, class A>
__device__ __forceinline__ void invoke(void (*f)(const R&, unsigned, A&), const void* rec,
                                       unsigned prim, void* attr) {
    f(*static_cast<const R*>(rec), prim, *static_cast<A*>(attr));
}
template <class R>
__device__ __forceinline__ unsigned invoke_visit(unsigned (*f)(const R&), const void* rec) {
    return f(*static_cast<const R*>(rec));
}
template <class R, class A>
__device__ __forceinline__ void invoke(void (*f)(const R&, unsigned, float2, A&), const void* rec,
                                       unsigned prim, float2 bary, void* attr) {
    f(*static_cast<const R*>(rec), prim, bary, *static_cast<A*>(attr));
}

template <class R, class Rec, class... P, class... A>
__device__ __forceinline__ R invoke_callable(R (*f)(const Rec&, P...), const void* rec, A... a) {
    return f(*static_cast<const Rec*>(rec), a...);
}

}  // namespace lucent::gpu

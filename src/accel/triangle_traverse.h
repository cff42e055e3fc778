// The entry points of the CPU triangle traversal (triangle_traverse.cpp), which is compiled
// once per instruction-set variant: each copy defines its own kTraverse in namespace
// isa_<variant>, and triangle_traverse_dispatch.cpp routes TriangleAccel's queries to the
// one the CPU runs (cpu_isa.h).
#pragma once

#include "accel/ray_stream.h"
#include "accel/triangle_accel.h"

namespace lucent::accel {

/// The type-erased filter of intersect_filtered (see triangle_accel_filtered.inl).
using FilterThunk = HitDecision (*)(void* filter, const TriangleHit& candidate);

/// One variant's queries, with TriangleAccel's meaning.
struct TraverseVariant {
    bool (*intersect)(const TriangleAccel::Impl& accel, float3 origin, float3 direction, float tmin,
                      float tmax, TriangleHit& hit);
    bool (*occluded)(const TriangleAccel::Impl& accel, float3 origin, float3 direction, float tmin,
                     float tmax);
    bool (*occluded_leaf_boxes)(const TriangleAccel::Impl& accel, float3 origin, float3 direction,
                                float tmin, float tmax);
    bool (*intersect_filtered)(const TriangleAccel::Impl& accel, float3 origin, float3 direction,
                               float tmin, float tmax, TriangleHit& hit, FilterThunk thunk,
                               void* filter);
    /// A batch of at most kStreamBatch rays (triangle_stream.cpp), in buffers reserved for it.
    void (*intersect_stream)(const TriangleAccel::Impl& accel, const StreamRay* rays, size_t count,
                             StreamHit* hits, StreamBuffers& buffers);
    void (*occluded_stream)(const TriangleAccel::Impl& accel, const StreamRay* rays, size_t count,
                            uint8_t* blocked, StreamBuffers& buffers);
    /// The code paths the variant's flags compiled in: "scalar", "avx2 fma" or
    /// "avx2 fma avx512vl" (the tests check each variant got what its name promises).
    const char* paths;
};

// Defined by the variants cmake/isa_variants.cmake builds (avx2 and avx512 on x86-64 only).
namespace isa_scalar {
extern const TraverseVariant kTraverse;
}
namespace isa_avx2 {
extern const TraverseVariant kTraverse;
}
namespace isa_avx512 {
extern const TraverseVariant kTraverse;
}

}  // namespace lucent::accel

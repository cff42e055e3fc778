// Lane refill: the megakernel's form of the dynamic fetch of Aila, Laine and Karras
// (NVR-2012-02, the Kepler addendum to Aila and Laine 2009). The bench kernels' traversal
// loop hands a lane whose ray is finished a new ray as soon as too few lanes of its warp are
// still busy. In the megakernel a finished lane cannot get a new ray inside the loop: what
// it runs next is the user's program (closest hit, the rest of its ray-generation program).
// Without refill it waits until every lane of its warp has finished its trace, so a warp
// tracing incoherent rays runs with a few lanes busy (7 of 32 on Sponza's diffuse rays,
// docs/performance.md).
//
// With refill (LUCENT_GPU_LANE_REFILL=1, launches on one GPU):
//  - each lane takes its next launch index alone when its program returns (lanes that arrive
//    together share one atomic, as in the bench kernels);
//  - trace()'s closest-hit traversal of a triangle group stops, for the lanes still busy,
//    once fewer than LUCENT_GPU_REFILL_THRESHOLD lanes are traversing, and waits at a
//    meeting (__syncwarp of the whole warp) at the top of the loop. The finished lanes run
//    on through their programs to their next trace(), which begins at that same meeting;
//    the lanes there go on traversing together.
//
// Every lane must come to every meeting, so a lane without work left does not leave the
// kernel but keeps meeting the others until all of its warp are without work. Each lane
// counts its meetings; all lanes' counts are equal after each meeting, so the last lane to
// run out can name the meeting after which all leave (`finish_at`), and none leaves while
// another still waits for it.
#pragma once

#include "lucent_gpu/runtime.cuh"
#include "lucent_gpu/triangle_bvh.cuh"

#ifndef LUCENT_GPU_REFILL_THRESHOLD
#define LUCENT_GPU_REFILL_THRESHOLD 24
#endif

namespace lucent::gpu {

#if LUCENT_GPU_LANE_REFILL

/// One warp's refill state (shared memory).
struct WarpRefill {
    unsigned retired;    // lanes without work left
    unsigned finish_at;  // the meeting after which every lane leaves; ~0 until known
};

__shared__ WarpRefill g_warp_refill[LUCENT_GPU_BLOCK / 32];

__device__ __forceinline__ WarpRefill& warp_refill() {
    return g_warp_refill[threadIdx.x >> 5];
}

/// Opens the warp's refill state; the whole warp calls it, converged, before any launch index.
__device__ __forceinline__ void refill_open(ThreadState& s) {
    if ((threadIdx.x & 31u) == 0) {
        warp_refill().retired = 0;
        warp_refill().finish_at = ~0u;
    }
    s.refill = 1;
    s.meetings = 0;
    __syncwarp();
}

/// A meeting of all 32 lanes of the warp (at whatever meeting each one is).
__device__ __forceinline__ void refill_meet(ThreadState& s) {
    __syncwarp();
    ++s.meetings;
}

/// The next launch index of each lane arriving here together: one atomic for the group.
__device__ __forceinline__ unsigned long long refill_claim(unsigned long long* counter) {
    const unsigned group = __activemask();
    const unsigned lane = threadIdx.x & 31u;
    const int leader = __ffs(group) - 1;
    unsigned long long base = 0;
    if ((int)lane == leader) base = atomicAdd(counter, (unsigned long long)__popc(group));
    base = __shfl_sync(group, base, leader);
    return base + (unsigned)__popc(group & ((1u << lane) - 1u));
}

/// A lane without work left: meets the others until every lane of the warp is without work.
__device__ __forceinline__ void refill_retire(ThreadState& s) {
    WarpRefill& w = warp_refill();
    // The last lane to retire names the meeting after its next: every lane reads the value
    // by then (the meeting orders memory), and all counts agree, so all leave together.
    if (atomicAdd(&w.retired, 1u) == 31u) w.finish_at = s.meetings + 2;
    for (;;) {
        refill_meet(s);
        if (s.meetings >= *(volatile unsigned*)&w.finish_at) return;
    }
}

/// The traversal's yield rule (GpuBvhTraversal::run with kDynamicFetch): stop below the
/// threshold, unless some lane of the warp has retired (then no lane can bring new work and
/// stopping would only add meetings) or this launch does not refill.
struct GpuRefillYield : GpuNoFilter {
    bool refill;
    __device__ __forceinline__ int yield_below() const {
        return refill && *(volatile unsigned*)&warp_refill().retired == 0
                   ? LUCENT_GPU_REFILL_THRESHOLD
                   : 0;
    }
};

/// Closest hit with t in (tmin, tmax), traversed with refill meetings (lane_refill.cuh).
__device__ __forceinline__ bool gpu_bvh_closest_refilled(const GpuTriangleBvhView& bvh,
                                                         float3 origin, float3 dir, float tmin,
                                                         float tmax, GpuHit& hit) {
    ThreadState& s = self();
    GpuBvhStack stack;
    GpuBvhTraversal tr;
    tr.start(origin, dir, tmin, tmax, stack);
    GpuRefillYield yield;
    yield.refill = s.refill != 0;
    for (;;) {
        // New traces and the lanes that stopped below the threshold meet here.
        if (yield.refill) refill_meet(s);
        tr.run<kGpuClosest, true>(bvh, yield, stack);
        if (tr.done()) break;
    }
    return tr.result(bvh, hit);
}

#endif  // LUCENT_GPU_LANE_REFILL

}  // namespace lucent::gpu

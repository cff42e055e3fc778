// The rays that ray-generation programs defer (trace_deferred() and occluded_deferred() of
// lucent/device/api.h): each worker of a CPU launch queues them while it runs launch
// indices, and traces the queue once it holds a ray stream's worth (kStreamBatch) and when
// its last index has run. Rays of a GeometryGroup of triangles whose candidates nothing
// needs to see are traced together as ray streams (accel/ray_stream.h, Barringer and
// Akenine-Möller 2014); then each ray's closest-hit or miss program runs on its payload, as
// at the end of trace(). Any other root traces its queued rays one by one, as trace() and
// occluded() would have.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "accel/ray_stream.h"
#include "cpu/launch_index.h"

namespace lucent::cpu {

/// A ray queued by trace_deferred(): the ray, where its payload lives, and who traced it.
struct DeferredTrace {
    Ray ray;
    Handle root;
    void* payload;  // in a buffer: the caller's program has returned when it is traced
    uint3 index;    // the launch index whose program deferred it
};

/// A ray queued by occluded_deferred(): the ray, the test, and the flag to set.
struct DeferredOcclusion {
    Ray ray;
    Handle root;
    Occlusion test;
    void* flag;                       // in a buffer, as DeferredTrace::payload
    void (*write_flag)(void*, bool);  // stores 1 or 0 in the caller's flag type
    uint3 index;
};

/// One worker's queue and the memory its streams work in, kept from launch to launch.
class DeferredRays {
  public:
    void add(const DeferredTrace& ray) { m_traces.push_back(ray); }
    void add(const DeferredOcclusion& ray) { m_occlusions.push_back(ray); }
    /// Enough rays for a stream to pay (session 38: incoherent rays gain from about 16K).
    bool full() const { return m_traces.size() + m_occlusions.size() >= accel::kStreamBatch; }
    /// Drops the queued rays untraced (a launch that failed).
    void clear() {
        m_traces.clear();
        m_occlusions.clear();
    }

    /// Traces every queued ray and runs its programs (closest hit or miss, or the flag's
    /// store), each with its launch index's thread state; an exception one raises runs the
    /// entry point's exception program for that index. Empties the queue.
    void trace_all(ThreadState& ts, const core::CompiledEntry& entry, WorkerExceptions& out);

  private:
    void trace_group(ThreadState& ts, const core::CompiledEntry& entry, WorkerExceptions& out,
                     std::span<const uint32_t> group);
    /// The built-in attributes of every hit of the stream (m_hits) into m_attributes.
    void compute_attributes(const core::CompiledScene& scene, const core::CompiledNode& n);
    void occlude_group(ThreadState& ts, const core::CompiledEntry& entry, WorkerExceptions& out,
                       std::span<const uint32_t> group);

    std::vector<DeferredTrace> m_traces;
    std::vector<DeferredOcclusion> m_occlusions;
    // The queue's positions grouped by what one query traces together, and where each
    // group ends (trace_all).
    std::vector<uint32_t> m_order;
    std::vector<size_t> m_group_ends;
    accel::RayStreamWorkspace m_workspace;
    std::vector<accel::StreamRay> m_stream;
    std::vector<accel::StreamHit> m_hits;
    std::vector<uint8_t> m_blocked;
    struct HitAttributes {  // a TriangleAttributes, as the frame's attribute bytes hold it
        alignas(8) unsigned char bytes[sizeof(TriangleAttributes)];
    };
    std::vector<HitAttributes> m_attributes;
};

}  // namespace lucent::cpu

// The rays that ray-generation programs defer (trace_deferred() and occluded_deferred() of
// lucent/device/api.h): each worker of a CPU launch queues them while it runs launch
// indices, and traces its queue once it holds a ray stream's worth (kStreamBatch); when
// the tiles are done, the workers share out the rays still queued and trace them. Rays of a
// GeometryGroup of triangles whose candidates nothing needs to see are traced together as ray
// streams (accel/ray_stream.h, Barringer and Akenine-Möller 2014); then each ray's closest-hit or
// miss program runs on its payload, as at the end of trace(). Any other root traces its queued rays
// one by one, as trace() and occluded() would have.
#pragma once

#include <cstdint>
#include <mutex>
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

/// One worker's queue of deferred rays, kept from launch to launch.
class DeferredQueue {
  public:
    void add(const DeferredTrace& ray) { m_traces.push_back(ray); }
    void add(const DeferredOcclusion& ray) { m_occlusions.push_back(ray); }
    /// Enough rays for a stream to pay (session 38: incoherent rays gain from about 16K).
    bool full() const { return m_traces.size() + m_occlusions.size() >= accel::kStreamBatch; }
    std::span<const DeferredTrace> traces() const { return m_traces; }
    std::span<const DeferredOcclusion> occlusions() const { return m_occlusions; }
    void clear() {
        m_traces.clear();
        m_occlusions.clear();
    }

  private:
    std::vector<DeferredTrace> m_traces;
    std::vector<DeferredOcclusion> m_occlusions;
};

/// Traces deferred rays and runs their programs (closest hit or miss, or the flag's store),
/// each with its launch index's thread state; an exception one raises runs the entry
/// point's exception program for that index. Any worker may trace any worker's rays. Its
/// memory (the streams' workspace, their hits) is a worker's, kept from launch to launch.
class DeferredTracer {
  public:
    void trace(ThreadState& ts, const core::CompiledEntry& entry, WorkerExceptions& out,
               std::span<const DeferredTrace> rays);
    void occlude(ThreadState& ts, const core::CompiledEntry& entry, WorkerExceptions& out,
                 std::span<const DeferredOcclusion> rays);
    /// A queue's rays, all of them (the queue stays as it is).
    void trace_all(ThreadState& ts, const core::CompiledEntry& entry, WorkerExceptions& out,
                   const DeferredQueue& queue) {
        trace(ts, entry, out, queue.traces());
        occlude(ts, entry, out, queue.occlusions());
    }

  private:
    void trace_group(ThreadState& ts, const core::CompiledEntry& entry, WorkerExceptions& out,
                     std::span<const DeferredTrace> rays, std::span<const uint32_t> group);
    /// The built-in attributes of every hit of the stream (m_hits) into m_attributes.
    void compute_attributes(const core::CompiledScene& scene, const core::CompiledNode& n);
    void occlude_group(ThreadState& ts, const core::CompiledEntry& entry, WorkerExceptions& out,
                       std::span<const DeferredOcclusion> rays, std::span<const uint32_t> group);

    // The rays' positions grouped by what one query traces together, and where each group
    // ends.
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

/// The rays the workers of a launch still hold when their tiles are done, shared out. A
/// worker's rays are those of the launch indices it happened to run, and running a
/// ray-generation program that defers its ray is fast: from one worker to another the
/// count can differ far more than the tiles' share, and a worker that traced only its own
/// rays would leave the others waiting (with each tracing its own, 16 workers ran the
/// deferred programs at 0.72x Embree's primary rays where one worker gave 1.22x, session 41). So each worker, its tiles done,
/// adds its queue in parts and then takes parts, the largest left first, its own or
/// another's, until none is left. Nobody waits for a worker that is late: its parts are
/// traced by itself and by whoever is still taking. (With a barrier before the taking, two
/// of four runs on 16 cores fell to 0.62x Embree's primary rays, session 41.)
class DeferredParts {
  public:
    /// Adds `queue`'s rays in parts; the queue must not change until the launch has ended.
    void add(const DeferredQueue& queue);
    /// The largest part left: rays of one kind (the other span empty); false when none is.
    bool take(std::span<const DeferredTrace>& traces,
              std::span<const DeferredOcclusion>& occlusions);

  private:
    struct Part {
        std::span<const DeferredTrace> traces;
        std::span<const DeferredOcclusion> occlusions;
        size_t size() const { return traces.size() + occlusions.size(); }
    };
    std::mutex m_mutex;
    std::vector<Part> m_parts;  // those not taken yet
};

}  // namespace lucent::cpu

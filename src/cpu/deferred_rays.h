// The rays that ray-generation programs defer (trace_deferred() and occluded_deferred() of
// lucent/device/api.h): each worker of a CPU launch queues them while it runs launch
// indices, and publishes its queue once it holds a ray stream's worth (kStreamBatch) and
// when its tiles are done; the workers trace the published rays, in runs that any of them
// may take (SharedDeferredRays). Rays of a GeometryGroup of triangles whose candidates
// nothing needs to see are traced together as ray streams (accel/ray_stream.h, Barringer and
// Akenine-Möller 2014); then each ray's closest-hit or miss program runs on its payload, as
// at the end of trace(). Any other root traces its rays one by one, as trace() and
// occluded() would have.
#pragma once

#include <atomic>
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
    /// A new entry at the end, for the caller to fill in.
    DeferredTrace& add_trace() { return m_traces.emplace_back(); }
    DeferredOcclusion& add_occlusion() { return m_occlusions.emplace_back(); }
    /// Enough rays for a stream to pay (session 38: incoherent rays gain from about 16K).
    bool full() const { return size() >= accel::kStreamBatch; }
    size_t size() const { return m_traces.size() + m_occlusions.size(); }
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

  private:
    /// Orders `rays` by what one query traces together (`key`: the root, and the ray type or
    /// the test) and calls trace_group() with each group's positions in `rays`.
    template <class Entry, class Key, class TraceGroup>
    void by_group(ThreadState& ts, std::span<const Entry> rays, Key key, TraceGroup trace_group);
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

/// The deferred rays of a launch's workers, shared among them. A worker's rays are those
/// of the launch indices it happened to run, and running a ray-generation program that
/// defers its ray is fast: from one worker to another the count differs far more than the
/// tiles' share. A worker that traced its own queue alone, when it is full and when its
/// tiles are done, would leave the others waiting: with each tracing its own, 16 workers ran
/// the deferred programs at 0.72x Embree's primary rays where one worker gave 1.22x
/// (session 41); and at 16 workers a 1024x768 launch is about 49K rays a worker, fewer
/// than one full queue's 65,536.
///
/// So a worker publishes its queue, when it is full and when its tiles are done, and every
/// worker takes runs of the published rays, its own first and then the largest queue's left:
/// the publisher until none is left, the others between their tiles and once their own
/// tiles are done. Each worker has two queues: when one is full and published, it queues in
/// the other, so that it need not wait for the runs of the first that others still trace
/// (waiting for them cost a third of the diffuse rays' speed on 2 cores). A worker whose
/// tiles are done does not leave while others still run theirs: it sleeps until rays are
/// published or the last tiles end, so that a late worker's rays are shared too (when each
/// left once nothing was left to take, a worker on 2 cores could trace alone for half the
/// launch).
///
/// A run is a share of the rays still to trace, as a run of tiles is of the tiles left
/// (OpenMP's guided schedule): long runs while many rays are to come, for a stream gains on
/// incoherent rays up to a whole queue's worth (Sponza's diffuse rays on 2 cores: 1.32-1.38x
/// Embree in runs of 64K, 1.03-1.16x in runs of 16K), and short ones at the end, so that the
/// workers finish together. The rays to come are those published and not taken, those
/// queued and not published, and those of the tiles not run yet, at the rate of the tiles
/// run so far.
class SharedDeferredRays {
  public:
    static constexpr unsigned kQueuesPerWorker = 2;
    /// Worker `worker`'s queue number `k` (< kQueuesPerWorker), as the calls below name it.
    static unsigned queue_id(unsigned worker, unsigned k) { return worker * kQueuesPerWorker + k; }

    /// For `workers` workers running `tiles` tiles.
    SharedDeferredRays(unsigned workers, uint64_t tiles)
        : m_queues(workers * kQueuesPerWorker),
          m_progress(workers),
          m_workers(workers),
          m_tiles(tiles),
          m_tiling(workers) {}

    /// A run of rays of one queue, of one kind (the other span empty).
    struct Run {
        unsigned queue = 0;  // its queue_id
        std::span<const DeferredTrace> traces;
        std::span<const DeferredOcclusion> occlusions;
    };

    /// Shares the rays of queue `id`, none of which it has published yet; the queue must not
    /// change until reclaim(id) has returned, or the launch has ended.
    void publish(unsigned id, const DeferredQueue& queue);
    /// `worker` has run one more tile, and holds `queued` rays not published.
    void tile_done(unsigned worker, size_t queued) {
        Progress& p = m_progress[worker];
        p.tiles.store(p.tiles.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
        p.queued.store(queued, std::memory_order_relaxed);
    }
    /// A worker has run its last tile and published its last rays (or failed).
    void end_tiles() {
        m_tiling.fetch_sub(1, std::memory_order_release);
        announce();
    }
    /// Do workers still run tiles, and so may publish more rays?
    bool tiles_running() const { return m_tiling.load(std::memory_order_acquire) != 0; }
    /// How many times rays were published or a worker's tiles ended, for wait_for_news().
    uint32_t news() const { return m_news.load(std::memory_order_acquire); }
    /// Sleeps until news() is no longer `seen`.
    void wait_for_news(uint32_t seen) const { m_news.wait(seen, std::memory_order_acquire); }
    /// Are published rays left to take? (A glance, without the lock.)
    bool any_left() const { return m_left.load(std::memory_order_relaxed) != 0; }
    /// The next run for `worker`, of its own queues if any is left; false when none is left.
    bool take(unsigned worker, Run& run);
    /// `run` is traced.
    void done(const Run& run);
    /// Returns when no run of queue `id` is being traced, and withdraws the rays of it not
    /// taken (none, unless the launch has failed and nobody takes any more): the queue may
    /// then change.
    void reclaim(unsigned id);

  private:
    void announce() {
        m_news.fetch_add(1, std::memory_order_release);
        m_news.notify_all();
    }
    /// How many rays are still to trace: published and not taken, and to come (under m_mutex).
    size_t rays_to_trace() const;

    struct Queue {  // what is left of a worker's published queue
        std::span<const DeferredTrace> traces;
        std::span<const DeferredOcclusion> occlusions;
        unsigned runs_out = 0;  // runs taken and not done
        size_t size() const { return traces.size() + occlusions.size(); }
    };
    std::mutex m_mutex;
    std::vector<Queue> m_queues;         // by queue_id
    struct alignas(64) Progress {        // a worker's, written by it alone (a cache line each)
        std::atomic<uint64_t> tiles{0};  // run
        std::atomic<size_t> queued{0};   // rays queued and not published
    };
    std::vector<Progress> m_progress;  // per worker
    const unsigned m_workers;
    const uint64_t m_tiles;
    size_t m_published = 0;          // rays published in all (under m_mutex)
    std::atomic<size_t> m_left{0};   // rays published and not taken (changed under m_mutex)
    std::atomic<unsigned> m_tiling;  // workers that have not called end_tiles()
    std::atomic<uint32_t> m_news{0};
};

}  // namespace lucent::cpu

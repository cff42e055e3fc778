#include "cpu/deferred_rays.h"

#include <algorithm>
#include <cstring>
#include <numeric>
#include <thread>
#include <utility>

#include "cpu/triangle_groups.h"

namespace lucent::cpu {

namespace {

using core::CompiledNode;
using core::CompiledScene;

/// Is a GeometryGroup of built-in triangles, on the host, that every ray sees (no
/// instance masked, the group's mask not 0): what a stream query answers alone.
bool streamable_group(const CompiledNode& n) {
    return n.kind == NodeKind::kGeometryGroup && n.geometry && n.geometry->triangles_only &&
           n.geometry->host_triangles && !n.instances_masked &&
           (n.visibility_mask & kVisibilityMaskAll) != 0;
}

/// Do the closest hits of deferred rays of `ray_type` from `root` come from the stream
/// query? They do where trace() would take the accel's closest hit: no any-hit program to
/// run (deferred rays have no flags that would need the candidates).
bool streams_trace(const CompiledScene& scene, Handle root, unsigned ray_type) {
    const CompiledNode& n = scene.nodes[root.index];
    return streamable_group(n) && !n.any_hit_for_ray_type[ray_type];
}

bool streams_occlusion(const CompiledScene& scene, Handle root, Occlusion test) {
    return test == Occlusion::kExact && streamable_group(scene.nodes[root.index]);
}

/// Orders the positions of `queue` into `order` so that the rays one query traces together
/// (the same `key`) lie next to each other, each key's in queue order and the keys in the
/// order of their first rays, and puts where each key's rays end into `ends`. Most launches
/// have one key. Both vectors keep their memory from call to call, so that a flush
/// allocates nothing once the first has run (a 256 KB buffer per call would be mapped and
/// unmapped by the allocator each time).
template <class Entry, class Key>
void order_by_key(std::span<const Entry> queue, Key key, std::vector<uint32_t>& order,
                  std::vector<size_t>& ends) {
    std::vector<std::pair<uint64_t, size_t>> counts;  // per key: its rays
    for (const Entry& e : queue) {
        const uint64_t k = key(e);
        auto it = counts.begin();
        while (it != counts.end() && it->first != k) ++it;
        if (it == counts.end())
            counts.push_back({k, 1});
        else
            ++it->second;
    }
    order.resize(queue.size());
    ends.clear();
    if (counts.size() <= 1) {  // the common case: the queue's order, without a second pass
        std::iota(order.begin(), order.end(), 0u);
        if (!counts.empty()) ends.push_back(queue.size());
        return;
    }
    std::vector<size_t> next;  // per key: where its next ray goes
    size_t end = 0;
    for (const auto& [k, count] : counts) {
        next.push_back(end);
        end += count;
        ends.push_back(end);
    }
    for (uint32_t i = 0; i < queue.size(); ++i) {
        size_t g = 0;
        while (counts[g].first != key(queue[i])) ++g;
        order[next[g]++] = i;
    }
}

/// How many hits ahead of the one whose attributes are computed its triangle's indices are
/// fetched (the vertices are fetched half as far ahead, once their indices have arrived).
/// A diffuse ray's hit triangle is anywhere in the mesh: without them each hit waits on
/// two misses.
constexpr size_t kIndicesAhead = 48, kVerticesAhead = 24;

/// Does every instance of the group take the built-in triangle attributes (no attribute
/// program)? Then they are computed for all hits ahead of the programs.
bool built_in_attributes(const CompiledScene& scene, const CompiledNode& n) {
    for (unsigned i : n.instances)
        if (scene.instances[i].attribute) return false;
    return true;
}

}  // namespace

template <class Entry, class Key, class TraceGroup>
void DeferredTracer::by_group(ThreadState& ts, std::span<const Entry> rays, Key key,
                              TraceGroup trace_group) {
    order_by_key(rays, key, m_order, m_group_ends);
    for (size_t g = 0, begin = 0; g < m_group_ends.size(); begin = m_group_ends[g++])
        trace_group(std::span<const uint32_t>(m_order).subspan(begin, m_group_ends[g] - begin));
    ts.depth = 0;
    ts.frame = nullptr;
}

void DeferredTracer::trace(ThreadState& ts, const core::CompiledEntry& entry, WorkerExceptions& out,
                           std::span<const DeferredTrace> rays) {
    by_group(
        ts, rays,
        [](const DeferredTrace& q) { return uint64_t(q.root.index) << 32 | q.ray.ray_type; },
        [&](std::span<const uint32_t> group) { trace_group(ts, entry, out, rays, group); });
}

void DeferredTracer::occlude(ThreadState& ts, const core::CompiledEntry& entry,
                             WorkerExceptions& out, std::span<const DeferredOcclusion> rays) {
    by_group(
        ts, rays,
        [](const DeferredOcclusion& q) { return uint64_t(q.root.index) << 32 | unsigned(q.test); },
        [&](std::span<const uint32_t> group) { occlude_group(ts, entry, out, rays, group); });
}

void DeferredTracer::trace_group(ThreadState& ts, const core::CompiledEntry& entry,
                                 WorkerExceptions& out, std::span<const DeferredTrace> rays,
                                 std::span<const uint32_t> group) {
    const CompiledScene& scene = *ts.scene;
    const CpuPolicy policy{&ts};
    const Handle root = rays[group[0]].root;
    const unsigned ray_type = rays[group[0]].ray.ray_type;
    // Checked against the ray type when the ray was deferred (trace_allowed).
    const void* payload_tag = scene.ray_types[ray_type].payload->tag;
    if (!streams_trace(scene, root, ray_type)) {
        for (uint32_t k : group) {
            const DeferredTrace& q = rays[k];
            enter_index(ts, q.index);
            try {
                runtime::trace(policy, q.root, q.ray, q.payload, payload_tag, kRayFlagNone,
                               kVisibilityMaskAll);
            } catch (const ProgramException& ex) {
                handle_program_exception(ts, entry, q.index, ex, out);
            }
        }
        return;
    }

    const CompiledNode& n = scene.nodes[root.index];
    m_stream.resize(group.size());
    m_hits.resize(group.size());
    for (size_t j = 0; j < group.size(); ++j) {
        const Ray& r = rays[group[j]].ray;
        m_stream[j] = accel::StreamRay{r.origin, r.tmin, r.direction, r.tmax};
    }
    n.geometry->triangles.intersect_stream(m_stream, m_hits, m_workspace);
    const bool built_in = built_in_attributes(scene, n);
    if (built_in) compute_attributes(scene, n);

    for (size_t j = 0; j < group.size(); ++j) {
        const DeferredTrace& q = rays[group[j]];
        const accel::StreamHit& hit = m_hits[j];
        enter_index(ts, q.index);
        try {
            // What trace() does after the accel's closest hit: a frame, the commit, shade.
            TraceFrame f;
            runtime::begin_frame<CpuPolicy>(f, q.ray, q.payload, /*occlusion=*/false, kRayFlagNone,
                                            kVisibilityMaskAll);
            ts.frame = &f;
            ts.depth = 1;
            if (hit.prim != accel::kStreamMiss) {
                unsigned instance, local;
                locate_triangle(n, hit.prim, instance, local);
                runtime::commit_triangle<CpuPolicy>(
                    f, instance, local, hit.t,
                    policy.primitive_material(scene.instances[instance], local),
                    make_float2(hit.u, hit.v));
                if (built_in) {  // computed above, as the single-ray path computes them at the hit
                    std::memcpy(f.hit_attr.bytes, m_attributes[j].bytes,
                                sizeof m_attributes[j].bytes);
                    f.hit_pending = false;
                }
            }
            runtime::shade(policy, f, q.ray);
            ts.depth = 0;
            ts.frame = nullptr;
        } catch (const ProgramException& ex) {
            handle_program_exception(ts, entry, q.index, ex, out);
        }
    }
}

void DeferredTracer::compute_attributes(const CompiledScene& scene, const CompiledNode& n) {
    m_attributes.resize(m_hits.size());
    const CpuPolicy policy{nullptr};  // its triangle() reads only the instance (no motion here)
    for (size_t j = 0; j < m_hits.size(); ++j) {
        if (j + kIndicesAhead < m_hits.size())
            prefetch_triangle_indices(scene, n, m_hits[j + kIndicesAhead].prim);
        if (j + kVerticesAhead < m_hits.size())
            prefetch_triangle_vertices(scene, n, m_hits[j + kVerticesAhead].prim);
        const accel::StreamHit& hit = m_hits[j];
        if (hit.prim == accel::kStreamMiss) continue;
        unsigned instance, local;
        locate_triangle(n, hit.prim, instance, local);
        float3 p0, p1, p2;
        policy.triangle(scene.instances[instance], local, p0, p1, p2);
        runtime::builtin_triangle_attributes(make_float2(hit.u, hit.v), p0, p1, p2,
                                             m_attributes[j]);
    }
}

void DeferredTracer::occlude_group(ThreadState& ts, const core::CompiledEntry& entry,
                                   WorkerExceptions& out, std::span<const DeferredOcclusion> rays,
                                   std::span<const uint32_t> group) {
    const CompiledScene& scene = *ts.scene;
    const Handle root = rays[group[0]].root;
    const Occlusion test = rays[group[0]].test;
    if (!streams_occlusion(scene, root, test)) {
        for (uint32_t k : group) {
            const DeferredOcclusion& q = rays[k];
            enter_index(ts, q.index);
            try {  // intersection programs may raise
                q.write_flag(q.flag,
                             occluded(ts, q.root, q.ray, q.test, kRayFlagNone, kVisibilityMaskAll));
            } catch (const ProgramException& ex) {
                handle_program_exception(ts, entry, q.index, ex, out);
            }
        }
        return;
    }
    m_stream.resize(group.size());
    m_blocked.resize(group.size());
    for (size_t j = 0; j < group.size(); ++j) {
        const Ray& r = rays[group[j]].ray;
        m_stream[j] = accel::StreamRay{r.origin, r.tmin, r.direction, r.tmax};
    }
    scene.nodes[root.index].geometry->triangles.occluded_stream(m_stream, m_blocked, m_workspace);
    for (size_t j = 0; j < group.size(); ++j) {
        const DeferredOcclusion& q = rays[group[j]];
        q.write_flag(q.flag, m_blocked[j] != 0);
    }
}

void SharedDeferredRays::publish(unsigned id, const DeferredQueue& queue) {
    {
        std::lock_guard lock(m_mutex);
        m_queues[id].traces = queue.traces();
        m_queues[id].occlusions = queue.occlusions();
        m_left += m_queues[id].size();
        m_published += m_queues[id].size();
        m_progress[id / kQueuesPerWorker].queued.store(0, std::memory_order_relaxed);
    }
    if (queue.size() != 0) announce();
}

size_t SharedDeferredRays::rays_to_trace() const {
    uint64_t tiles_run = 0;
    size_t queued = 0;
    for (const Progress& p : m_progress) {
        tiles_run += p.tiles.load(std::memory_order_relaxed);
        queued += p.queued.load(std::memory_order_relaxed);
    }
    const double per_tile = tiles_run ? double(m_published + queued) / double(tiles_run) : 0.0;
    const uint64_t tiles_left = m_tiles - std::min(m_tiles, tiles_run);
    return m_left.load(std::memory_order_relaxed) + queued + size_t(per_tile * double(tiles_left));
}

bool SharedDeferredRays::take(unsigned worker, Run& run) {
    // Runs of 1K rays at least, where a stream still pays on coherent rays, and a whole
    // queue at most.
    constexpr size_t kShortest = 1024, kLongest = accel::kStreamBatch;
    if (!any_left())
        return false;  // without the lock: workers that wait for others' tiles ask often
    std::lock_guard lock(m_mutex);  // some dozens of runs a launch: a scan of the queues is nothing
    const size_t left = m_left.load(std::memory_order_relaxed);
    if (left == 0) return false;
    Queue* from = &m_queues[queue_id(worker, 0)];
    for (unsigned k = 1; k < kQueuesPerWorker && from->size() == 0; ++k)
        from = &m_queues[queue_id(worker, k)];
    if (from->size() == 0)
        from =
            &*std::max_element(m_queues.begin(), m_queues.end(),
                               [](const Queue& a, const Queue& b) { return a.size() < b.size(); });
    const size_t n = std::clamp(rays_to_trace() / (2 * size_t(m_workers)), kShortest, kLongest);
    run.queue = unsigned(from - m_queues.data());
    run.traces = from->traces.first(std::min(n, from->traces.size()));
    from->traces = from->traces.subspan(run.traces.size());
    run.occlusions = {};
    if (run.traces.empty()) {
        run.occlusions = from->occlusions.first(std::min(n, from->occlusions.size()));
        from->occlusions = from->occlusions.subspan(run.occlusions.size());
    }
    ++from->runs_out;
    m_left.store(left - run.traces.size() - run.occlusions.size(), std::memory_order_relaxed);
    return true;
}

void SharedDeferredRays::done(const Run& run) {
    std::lock_guard lock(m_mutex);
    --m_queues[run.queue].runs_out;
}

void SharedDeferredRays::reclaim(unsigned id) {
    for (;;) {
        {
            std::lock_guard lock(m_mutex);
            Queue& q = m_queues[id];
            if (q.runs_out == 0) {
                m_left.store(m_left.load(std::memory_order_relaxed) - q.size(),
                             std::memory_order_relaxed);
                q.traces = {};
                q.occlusions = {};
                return;
            }
        }
        std::this_thread::yield();
    }
}

}  // namespace lucent::cpu

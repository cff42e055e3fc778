#include "cpu/deferred_rays.h"

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

/// The positions in `queue` of each run of rays that one query traces together (the same
/// `key`), in the order of each key's first ray: most launches have one.
template <class Entry, class Key>
std::vector<std::vector<uint32_t>> groups_of(const std::vector<Entry>& queue, Key key) {
    std::vector<std::pair<uint64_t, std::vector<uint32_t>>> groups;
    for (uint32_t i = 0; i < queue.size(); ++i) {
        const uint64_t k = key(queue[i]);
        auto it = groups.begin();
        while (it != groups.end() && it->first != k) ++it;
        if (it == groups.end()) it = groups.insert(groups.end(), {k, {}});
        it->second.push_back(i);
    }
    std::vector<std::vector<uint32_t>> out;
    for (auto& g : groups) out.push_back(std::move(g.second));
    return out;
}

/// How many rays ahead of the one being shaded the hit triangles' indices are fetched (the
/// vertices are fetched half as far ahead, once their indices have arrived). A diffuse
/// ray's hit triangle is anywhere in the mesh; its attributes, computed at shade time,
/// would otherwise wait on two misses per ray.
constexpr size_t kIndicesAhead = 16, kVerticesAhead = 8;

}  // namespace

void DeferredRays::trace_all(ThreadState& ts, const core::CompiledEntry& entry,
                             WorkerExceptions& out) {
    for (const auto& group : groups_of(m_traces, [](const DeferredTrace& q) {
             return uint64_t(q.root.index) << 32 | q.ray.ray_type;
         }))
        trace_group(ts, entry, out, group);
    for (const auto& group : groups_of(m_occlusions, [](const DeferredOcclusion& q) {
             return uint64_t(q.root.index) << 32 | unsigned(q.test);
         }))
        occlude_group(ts, entry, out, group);
    m_traces.clear();
    m_occlusions.clear();
    ts.depth = 0;
    ts.frame = nullptr;
}

void DeferredRays::trace_group(ThreadState& ts, const core::CompiledEntry& entry,
                               WorkerExceptions& out, const std::vector<uint32_t>& group) {
    const CompiledScene& scene = *ts.scene;
    const CpuPolicy policy{&ts};
    const Handle root = m_traces[group[0]].root;
    const unsigned ray_type = m_traces[group[0]].ray.ray_type;
    // Checked against the ray type when the ray was deferred (trace_allowed).
    const void* payload_tag = scene.ray_types[ray_type].payload->tag;
    if (!streams_trace(scene, root, ray_type)) {
        for (uint32_t k : group) {
            const DeferredTrace& q = m_traces[k];
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
        const Ray& r = m_traces[group[j]].ray;
        m_stream[j] = accel::StreamRay{r.origin, r.tmin, r.direction, r.tmax};
    }
    n.geometry->triangles.intersect_stream(m_stream, m_hits, m_workspace);

    for (size_t j = 0; j < group.size(); ++j) {
        if (j + kIndicesAhead < group.size())
            prefetch_triangle_indices(scene, n, m_hits[j + kIndicesAhead].prim);
        if (j + kVerticesAhead < group.size())
            prefetch_triangle_vertices(scene, n, m_hits[j + kVerticesAhead].prim);
        const DeferredTrace& q = m_traces[group[j]];
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
            }
            runtime::shade(policy, f, q.ray);
            ts.depth = 0;
            ts.frame = nullptr;
        } catch (const ProgramException& ex) {
            handle_program_exception(ts, entry, q.index, ex, out);
        }
    }
}

void DeferredRays::occlude_group(ThreadState& ts, const core::CompiledEntry& entry,
                                 WorkerExceptions& out, const std::vector<uint32_t>& group) {
    const CompiledScene& scene = *ts.scene;
    const Handle root = m_occlusions[group[0]].root;
    const Occlusion test = m_occlusions[group[0]].test;
    if (!streams_occlusion(scene, root, test)) {
        for (uint32_t k : group) {
            const DeferredOcclusion& q = m_occlusions[k];
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
        const Ray& r = m_occlusions[group[j]].ray;
        m_stream[j] = accel::StreamRay{r.origin, r.tmin, r.direction, r.tmax};
    }
    scene.nodes[root.index].geometry->triangles.occluded_stream(m_stream, m_blocked, m_workspace);
    for (size_t j = 0; j < group.size(); ++j) {
        const DeferredOcclusion& q = m_occlusions[group[j]];
        q.write_flag(q.flag, m_blocked[j] != 0);
    }
}

}  // namespace lucent::cpu

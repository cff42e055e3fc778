// The CPU's traversal: walks the compiled graph (Groups, Transforms, Selectors,
// GeometryGroups) and drives the trace state machine of runtime/trace_rules.h, which runs
// intersection and any-hit programs as primitives are found, then closest hit or miss
// (OptiX paper §3.1, Fig. 2: Traverse, then Shade). The GPU's traversal drives the same.
#include <algorithm>

#include "cpu/cpu_state.h"
#include "cpu/triangle_groups.h"
#include "lucent/device/triangle_intersect.h"
#include "lucent/error.h"

namespace lucent::cpu {

namespace {

using core::CompiledInstance;
using core::CompiledNode;
using core::CompiledScene;

/// Walks the compiled graph for one trace frame; the steps of the trace state machine
/// (runtime/trace_rules.h) run the programs.
class Traverser {
  public:
    Traverser(ThreadState& ts, TraceFrame& frame)
        : m_policy{&ts}, m_frame(frame), m_scene(*ts.scene) {}

    void node(unsigned index, float3 origin, float3 direction) {
        const CompiledNode& n = m_scene.nodes[index];
        if (!runtime::visible(m_frame, n.visibility_mask)) return;
        switch (n.kind) {
            case NodeKind::kGeometryGroup:
                geometry_group(n, origin, direction);
                break;
            case NodeKind::kGroup:
                group(n, origin, direction);
                break;
            case NodeKind::kTransform:
                transform(n, origin, direction);
                break;
            case NodeKind::kSelector:
                selector(n, origin, direction);
                break;
        }
    }

    /// The walk from the trace's root. The common root of a closest-hit trace, a
    /// GeometryGroup of triangles whose candidates nothing needs to see, goes straight to
    /// its accel, without the graph's dispatch and the general group's large stack frame:
    /// 3-5 % off a primary or diffuse ray's time in the engine (docs/performance.md).
    void root(unsigned index) {
        const CompiledNode& n = m_scene.nodes[index];
        const float3 origin = m_frame.world_ray.origin, direction = m_frame.world_ray.direction;
        if (n.kind == NodeKind::kGeometryGroup && n.geometry && n.geometry->triangles_only &&
            !m_frame.occlusion && !trace_needs_candidates(n)) {
            if (!runtime::visible(m_frame, n.visibility_mask)) return;
            runtime::enter_space<CpuPolicy>(m_frame, origin, direction);
            m_frame.masked_instances = false;  // trace_needs_candidates: none is masked
            closest_triangle(n, origin, direction);
            return;
        }
        node(index, origin, direction);
    }

  private:
    void group(const CompiledNode& n, float3 origin, float3 direction) {
        auto visit = [&](uint32_t child) {
            node(n.children[child], origin, direction);
            return m_frame.terminated;
        };
        if (n.brute_force) {
            for (uint32_t c = 0; c < n.children.size(); ++c)
                if (visit(c)) return;
        } else {
            n.child_bvh.traverse(origin, direction, m_frame.world_ray.tmin, m_frame.closest, visit);
        }
    }

    void transform(const CompiledNode& n, float3 origin, float3 direction) {
        if (runtime::moving(n.motion)) {
            // The keys interpolated at the ray's time; nothing below when it vanished.
            Matrix4x3 to_world, to_object;
            if (runtime::motion_transform_at(m_scene.motion.data(), n.motion,
                                             m_frame.world_ray.time, to_world, to_object))
                enter(n, to_world, to_object, origin, direction);
            return;
        }
        enter(n, n.to_world, n.to_object, origin, direction);
    }
    void enter(const CompiledNode& n, const Matrix4x3& to_world, const Matrix4x3& to_object,
               float3 origin, float3 direction) {
        const runtime::SavedTransform saved =
            runtime::enter_transform(m_frame, to_world, to_object, n.instance_id);
        node(n.children[0], transform_point(to_object, origin),
             transform_vector(to_object, direction));
        runtime::leave_transform(m_frame, saved);
    }

    void selector(const CompiledNode& n, float3 origin, float3 direction) {
        const unsigned child = runtime::run_visit(m_policy, m_frame, &n.visit, origin, direction);
        if (child < n.children.size()) node(n.children[child], origin, direction);
    }

    void geometry_group(const CompiledNode& n, float3 origin, float3 direction) {
        const core::GeometryAccel& ga = *n.geometry;
        runtime::enter_space<CpuPolicy>(m_frame, origin, direction);
        m_frame.masked_instances = n.instances_masked;
        const float tmin = m_frame.world_ray.tmin;
        if (ga.triangles_only) {
            accel::TriangleHit hit;
            if (m_frame.occlusion) {
                if (!occlusion_needs_candidates(n)) {
                    const bool blocked =
                        m_frame.leaf_boxes
                            ? ga.triangles.occluded_leaf_boxes(origin, direction, tmin,
                                                               m_frame.closest)
                            : ga.triangles.occluded(origin, direction, tmin, m_frame.closest);
                    if (blocked) m_frame.has_hit = m_frame.terminated = true;
                    return;
                }
            } else if (!trace_needs_candidates(n)) {
                closest_triangle(n, origin, direction);
                return;
            }
            // Each candidate through the trace state machine: any-hit, masks, culls.
            ga.triangles.intersect_filtered(
                origin, direction, tmin, m_frame.closest, hit, [&](const accel::TriangleHit& c) {
                    if (!(c.t < m_frame.closest)) return accel::HitDecision::kIgnore;
                    if (!triangle_any_hit(n, c.prim, c.t, make_float2(c.u, c.v)))
                        return accel::HitDecision::kIgnore;
                    return m_frame.terminated ? accel::HitDecision::kAcceptAndStop
                                              : accel::HitDecision::kAccept;
                });
            return;
        }
        WatertightRay wray = make_watertight_ray(origin, direction);
        auto visit = [&](uint32_t ref) {
            // The instance owning global primitive `ref`.
            size_t k = std::upper_bound(ga.prim_first.begin(), ga.prim_first.end(), ref) -
                       ga.prim_first.begin() - 1;
            unsigned local = ref - ga.prim_first[k];
            const CompiledInstance& inst = m_scene.instances[n.instances[k]];
            if (inst.triangles()) {
                uint3 tri = inst.triangle(local);
                float3 p0 = inst.vertices[tri.x], p1 = inst.vertices[tri.y],
                       p2 = inst.vertices[tri.z];
                if (runtime::moving(inst.motion) &&
                    !m_policy.moving_triangle(inst, tri, m_frame.world_ray.time, p0, p1, p2))
                    return false;
                float t, u, v;
                if (intersect_triangle_watertight(wray, p0, p1, p2, tmin, m_frame.closest, t, u, v))
                    runtime::triangle_candidate(m_policy, m_frame, n.instances[k], local, t,
                                                make_float2(u, v));
            } else if (inst.type == PrimitiveType::kSpheres) {
                float3 center = inst.centers[local];
                if (runtime::moving(inst.motion) &&
                    !runtime::motion_center(m_scene.motion.data(), inst.motion, inst.motion_points,
                                            local, m_frame.world_ray.time, center))
                    return false;
                runtime::sphere_candidates(m_policy, m_frame, n.instances[k], local, origin,
                                           direction, center, inst.radius(local));
            } else if (inst.type == PrimitiveType::kCurves) {
                runtime::curve_candidates(m_policy, m_frame, n.instances[k], local, origin,
                                          direction, inst.curve_type, inst.vertices, inst.radii,
                                          inst.segments);
            } else {
                runtime::run_intersection(m_policy, m_frame, n.instances[k], inst, local);
            }
            return m_frame.terminated;
        };
        if (n.brute_force) {
            uint32_t total =
                ga.prim_first.empty()
                    ? 0
                    : ga.prim_first.back() +
                          m_scene.instances[n.instances.back()].bvh_references();
            for (uint32_t ref = 0; ref < total; ++ref)
                if (visit(ref)) return;
        } else {
            ga.bvh.traverse(origin, direction, tmin, m_frame.closest, visit);
        }
    }

    // ---- triangles -------------------------------------------------------------------
    /// Must a trace see each triangle of this group (any-hit programs to run, instances
    /// masked, culls or kRayFlagTerminateOnFirstHit), or does the closest one answer it?
    bool trace_needs_candidates(const CompiledNode& n) const {
        const unsigned flags = m_frame.ray_flags;
        if ((flags & runtime::kRayFlagsPerCandidate) || n.instances_masked) return true;
        if (flags & kRayFlagDisableAnyHit) return false;
        return flags & kRayFlagEnforceAnyHit ? n.any_hit_enforced_for_ray_type[m_frame.ray_type]
                                             : n.any_hit_for_ray_type[m_frame.ray_type];
    }
    /// Must occluded() see each triangle (a facing cull, masked instances)? Leaf boxes then
    /// give way to the exact test: a leaf box mixes instances and loads no triangle.
    bool occlusion_needs_candidates(const CompiledNode& n) const {
        return (m_frame.ray_flags & kRayFlagsFacingCull) || n.instances_masked;
    }

    /// The closest triangle of a group without any-hit programs: committed, its attributes
    /// computed at shade time.
    void commit_triangle(const CompiledNode& n, unsigned global, float t, float2 bary) {
        unsigned instance, local;
        locate_triangle(n, global, instance, local);
        runtime::commit_triangle<CpuPolicy>(
            m_frame, instance, local, t,
            m_policy.primitive_material(m_scene.instances[instance], local), bary);
    }

    /// The closest triangle of a triangles-only group without any-hit programs, found by
    /// its accel: committed with its attributes, computed now from the vertices in the leaf
    /// the traversal just tested. Left for the shade phase, they were read from the mesh's
    /// own arrays, often out of cache (a fifth of a diffuse ray's time on Sponza). An
    /// instance with an attribute program keeps the shade-time path.
    void commit_closest_triangle(const CompiledNode& n, const accel::TriangleHit& hit) {
        const float2 bary = make_float2(hit.u, hit.v);
        commit_triangle(n, hit.prim, hit.t, bary);
        if (m_policy.bound(m_policy.attribute(m_scene.instances[m_frame.hit_instance]))) return;
        float3 p0, p1, p2;
        accel::hit_vertices(hit, p0, p1, p2);
        runtime::builtin_triangle_attributes(bary, p0, p1, p2, m_frame.hit_attr);
        m_frame.hit_pending = false;
    }

    /// The closest triangle of a triangles-only group, found by its accel and committed:
    /// for a trace whose candidates no any-hit program, mask or flag needs to see.
    void closest_triangle(const CompiledNode& n, float3 origin, float3 direction) {
        accel::TriangleHit hit;
        if (n.geometry->triangles.intersect(origin, direction, m_frame.world_ray.tmin,
                                            m_frame.closest, hit))
            commit_closest_triangle(n, hit);
    }

    /// Runs any-hit for a triangle candidate; returns true when it was accepted (committed).
    bool triangle_any_hit(const CompiledNode& n, unsigned global, float t, float2 bary) {
        unsigned instance, local;
        locate_triangle(n, global, instance, local);
        return runtime::triangle_candidate(m_policy, m_frame, instance, local, t, bary);
    }

    CpuPolicy m_policy;
    TraceFrame& m_frame;
    const CompiledScene& m_scene;
};

}  // namespace

void CpuPolicy::traverse_frame(TraceFrame& frame, Handle root) const {
    Traverser(*ts, frame).root(root.index);
}

void require_occluded_declared(const CompiledScene& scene) {
    if (!scene.uses_occluded)  // the GPU's megakernel would not compile this call either
        throw Error(
            "occluded() or occluded_deferred() is called, but no module of this scene "
            "declares it; declare it in the module that calls it: LUCENT_MODULE(name, "
            "lucent::kUsesOccluded)");
}

bool occluded(ThreadState& ts, Handle root, const Ray& ray, Occlusion test, unsigned ray_flags,
              unsigned ray_mask) {
    const CompiledScene& scene = *ts.scene;
    require_occluded_declared(scene);
    const CpuPolicy policy{&ts};
    const bool leaf_boxes = test == Occlusion::kLeafBoxes;
    // Raises (throws) on bad input.
    runtime::occlusion_allowed(policy, root, ray, leaf_boxes, ray_flags, ray_mask);
    // A GeometryGroup of triangles (the common shadow root): the BVH's any-hit traversal.
    const CompiledNode& root_node = scene.nodes[root.index];
    if (root_node.kind == NodeKind::kGeometryGroup && root_node.geometry &&
        root_node.geometry->triangles_only && !(ray_flags & kRayFlagsFacingCull) &&
        !root_node.instances_masked) {
        if (!(root_node.visibility_mask & ray_mask)) return false;
        const accel::TriangleAccel& triangles = root_node.geometry->triangles;
        return leaf_boxes
                   ? triangles.occluded_leaf_boxes(ray.origin, ray.direction, ray.tmin, ray.tmax)
                   : triangles.occluded(ray.origin, ray.direction, ray.tmin, ray.tmax);
    }
    // Anything else needs a frame: intersection programs, selectors, masks and culls.
    return runtime::occluded_in_frame(policy, root, ray, leaf_boxes, ray_flags, ray_mask);
}

}  // namespace lucent::cpu

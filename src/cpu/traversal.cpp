// trace() on the CPU: walks the compiled graph (Groups, Transforms, Selectors,
// GeometryGroups), runs intersection and any-hit programs as it finds primitives, then
// the closest-hit or miss program (OptiX paper §3.1, Fig. 2: Traverse, then Shade).
#include <algorithm>
#include <cstring>

#include "cpu/cpu_state.h"
#include "lucent/error.h"
#include "lucent/device/triangle_intersect.h"

namespace lucent::cpu {

namespace {

using core::CompiledInstance;
using core::CompiledNode;
using core::CompiledScene;

constexpr Matrix4x3 kIdentity{{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}};

/// a ∘ b for affine matrices (apply b first).
Matrix4x3 compose(const Matrix4x3& a, const Matrix4x3& b) {
    Matrix4x3 r;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 4; ++j) {
            float v = a.m[i * 4 + 0] * b.m[0 * 4 + j] + a.m[i * 4 + 1] * b.m[1 * 4 + j] +
                      a.m[i * 4 + 2] * b.m[2 * 4 + j];
            if (j == 3) v += a.m[i * 4 + 3];
            r.m[i * 4 + j] = v;
        }
    }
    return r;
}

uint3 triangle_of(const CompiledInstance& inst, unsigned prim) {
    return inst.indices ? inst.indices[prim] : uint3{3 * prim, 3 * prim + 1, 3 * prim + 2};
}

class Traverser {
  public:
    Traverser(ThreadState& ts, TraceFrame& frame) : m_ts(ts), m_frame(frame), m_scene(*ts.scene) {}

    void node(unsigned index, float3 origin, float3 direction) {
        const CompiledNode& n = m_scene.nodes[index];
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
        // Rays enter the child's space; the direction is not renormalised, so t is the same
        // in every space and hits compare across transforms.
        const bool was = m_frame.transformed;
        const Matrix4x3 to_world = m_frame.to_world, to_object = m_frame.to_object;
        m_frame.to_world = was ? compose(to_world, n.to_world) : n.to_world;
        m_frame.to_object = was ? compose(n.to_object, to_object) : n.to_object;
        m_frame.transformed = true;
        node(n.children[0], transform_point(n.to_object, origin),
             transform_vector(n.to_object, direction));
        m_frame.transformed = was;
        m_frame.to_world = to_world;
        m_frame.to_object = to_object;
    }

    void selector(const CompiledNode& n, float3 origin, float3 direction) {
        set_object_ray(origin, direction);
        ProgramContext saved = m_frame.context;
        m_frame.context = ProgramContext::kVisit;
        unsigned child = n.visit.entry<VisitFn>()(n.visit.rec());
        m_frame.context = saved;
        if (child < n.children.size()) node(n.children[child], origin, direction);
    }

    void geometry_group(const CompiledNode& n, float3 origin, float3 direction) {
        const core::GeometryAccel& ga = *n.geometry;
        set_object_ray(origin, direction);
        const float tmin = m_frame.world_ray.tmin;
        if (ga.triangles_only) {
            accel::TriangleHit hit;
            if (m_frame.occlusion) {
                if (ga.triangles.occluded(origin, direction, tmin, m_frame.closest))
                    m_frame.has_hit = m_frame.terminated = true;
                return;
            }
            if (!n.any_hit_for_ray_type[m_frame.ray_type]) {
                if (ga.triangles.intersect(origin, direction, tmin, m_frame.closest, hit))
                    commit_triangle(n, hit.prim, hit.t, make_float2(hit.u, hit.v));
                return;
            }
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
            if (inst.triangles) {
                uint3 tri = triangle_of(inst, local);
                float t, u, v;
                if (intersect_triangle_watertight(wray, inst.vertices[tri.x], inst.vertices[tri.y],
                                                  inst.vertices[tri.z], tmin, m_frame.closest, t, u,
                                                  v)) {
                    unsigned global_tri = ref;  // prim_first doubles as the triangle numbering
                    triangle_candidate(n, global_tri, k, local, t, make_float2(u, v));
                }
            } else {
                custom_primitive(n.instances[k], inst, local);
            }
            return m_frame.terminated;
        };
        if (n.brute_force) {
            uint32_t total =
                ga.prim_first.empty()
                    ? 0
                    : ga.prim_first.back() + m_scene.instances[n.instances.back()].primitive_count;
            for (uint32_t ref = 0; ref < total; ++ref)
                if (visit(ref)) return;
        } else {
            ga.bvh.traverse(origin, direction, tmin, m_frame.closest, visit);
        }
    }

    // ---- triangles -------------------------------------------------------------------
    /// Global triangle → (position in the group, local index).
    void locate_triangle(const CompiledNode& n, unsigned global, size_t& k, unsigned& local) const {
        const core::GeometryAccel& ga = *n.geometry;
        k = ga.triangles_only
                ? ga.tri_instance[global]
                : size_t(std::upper_bound(ga.prim_first.begin(), ga.prim_first.end(), global) -
                         ga.prim_first.begin() - 1);
        local = global - ga.prim_first[k];
    }

    void commit_triangle(const CompiledNode& n, unsigned global, float t, float2 bary) {
        size_t k;
        unsigned local;
        locate_triangle(n, global, k, local);
        const CompiledInstance& inst = m_scene.instances[n.instances[k]];
        begin_commit(n.instances[k], local, t,
                     inst.material_indices ? inst.material_indices[local] : 0u);
        m_frame.hit.barycentrics = bary;
        m_frame.hit.attributes_pending = true;
    }

    /// Runs any-hit for a triangle candidate; returns true when it was accepted (committed).
    bool triangle_any_hit(const CompiledNode& n, unsigned global, float t, float2 bary) {
        size_t k;
        unsigned local;
        locate_triangle(n, global, k, local);
        return triangle_candidate(n, global, k, local, t, bary);
    }

    bool triangle_candidate(const CompiledNode& n, unsigned, size_t k, unsigned local, float t,
                            float2 bary) {
        if (m_frame.occlusion) {  // any intersection answers the query
            m_frame.has_hit = m_frame.terminated = true;
            return true;
        }
        unsigned instance_index = n.instances[k];
        const CompiledInstance& inst = m_scene.instances[instance_index];
        unsigned material = inst.material_indices ? inst.material_indices[local] : 0u;
        const core::CompiledProgram& any_hit = inst.materials[material].any_hit[m_frame.ray_type];
        if (!any_hit) {
            begin_commit(instance_index, local, t, material);
            m_frame.hit.barycentrics = bary;
            m_frame.hit.attributes_pending = true;
            return true;
        }
        m_frame.instance = &inst;
        m_frame.instance_index = instance_index;
        m_frame.prim = local;
        compute_triangle_attributes(m_ts, inst, local, bary, m_frame.scratch);
        m_frame.candidate_t = t;
        if (!run_any_hit(any_hit)) return false;
        begin_commit(instance_index, local, t, material);
        m_frame.hit.barycentrics = bary;
        std::memcpy(m_frame.hit.attributes.bytes, m_frame.scratch.bytes, inst.attributes->size);
        return true;
    }

  public:
    /// Fills `out` with the attributes of a triangle hit: the attribute program's, or the
    /// built-in TriangleAttributes (barycentrics and object-space geometric normal).
    static void compute_triangle_attributes(ThreadState& ts, const CompiledInstance& inst,
                                            unsigned prim, float2 bary, AttributeStorage& out) {
        if (inst.attribute) {
            TraceFrame* f = ts.current();
            ProgramContext saved = f->context;
            f->context = ProgramContext::kAttribute;
            inst.attribute.entry<AttributeFn>()(inst.attribute.rec(), prim, bary, out.bytes);
            f->context = saved;
            return;
        }
        uint3 tri = triangle_of(inst, prim);
        float3 p0 = inst.vertices[tri.x], p1 = inst.vertices[tri.y], p2 = inst.vertices[tri.z];
        TriangleAttributes a;
        a.barycentrics = bary;
        a.geometric_normal = normalize(cross(p1 - p0, p2 - p0));
        std::memcpy(out.bytes, &a, sizeof a);
    }

  private:
    // ---- custom primitives ---------------------------------------------------------------
    void custom_primitive(unsigned instance_index, const CompiledInstance& inst, unsigned prim) {
        m_frame.instance = &inst;
        m_frame.instance_index = instance_index;
        m_frame.prim = prim;
        ProgramContext saved = m_frame.context;
        m_frame.context = ProgramContext::kIntersection;
        inst.intersection.entry<IntersectionFn>()(inst.intersection.rec(), prim,
                                                  m_frame.scratch.bytes);
        m_frame.context = saved;
    }

    void set_object_ray(float3 origin, float3 direction) {
        m_frame.object_ray = m_frame.world_ray;
        m_frame.object_ray.origin = origin;
        m_frame.object_ray.direction = direction;
    }

  public:
    /// Runs an any-hit program on the candidate in the frame; false when it was ignored.
    static bool run_any_hit(TraceFrame& frame, const core::CompiledProgram& any_hit) {
        ProgramContext saved = frame.context;
        frame.context = ProgramContext::kAnyHit;
        frame.ignore_requested = false;
        frame.terminate_requested = false;
        any_hit.entry<HitFn>()(any_hit.rec(), frame.payload, frame.scratch.bytes);
        frame.context = saved;
        if (frame.ignore_requested) return false;
        if (frame.terminate_requested) frame.terminated = true;
        return true;
    }

    /// Records a hit as the closest so far (attributes are filled by the caller).
    static void commit(TraceFrame& frame, unsigned instance, unsigned prim, float t,
                       unsigned material) {
        frame.has_hit = true;
        frame.closest = t;
        HitState& h = frame.hit;
        h.t = t;
        h.instance = instance;
        h.prim = prim;
        h.material = material;
        h.attributes_pending = false;
        h.transformed = frame.transformed;
        if (frame.transformed) {
            h.to_world = frame.to_world;
            h.to_object = frame.to_object;
        }
    }

  private:
    bool run_any_hit(const core::CompiledProgram& any_hit) { return run_any_hit(m_frame, any_hit); }
    void begin_commit(unsigned instance, unsigned prim, float t, unsigned material) {
        commit(m_frame, instance, prim, t, material);
    }

    ThreadState& m_ts;
    TraceFrame& m_frame;
    const CompiledScene& m_scene;
};

}  // namespace

/// report_intersection() of the device API: the candidate set by potential_intersection.
bool report_candidate(ThreadState& ts, unsigned material) {
    TraceFrame* f = ts.current();
    if (!f || f->context != ProgramContext::kIntersection || !f->candidate_open) return false;
    f->candidate_open = false;
    const CompiledInstance& inst = *f->instance;
    if (material >= inst.materials.size())
        throw ProgramException{kExceptionMaterialIndexOutOfRange, material};
    if (f->occlusion) {  // occluded(): no any-hit, the first intersection ends traversal
        f->has_hit = f->terminated = true;
        return true;
    }
    const core::CompiledProgram& any_hit = inst.materials[material].any_hit[f->ray_type];
    if (any_hit && !Traverser::run_any_hit(*f, any_hit)) return false;
    Traverser::commit(*f, f->instance_index, f->prim, f->candidate_t, material);
    std::memcpy(f->hit.attributes.bytes, f->scratch.bytes, inst.attributes->size);
    return true;
}

namespace {
/// The next trace frame of `ts`, set up for `ray` before traversal (the caller pops it).
TraceFrame& push_frame(ThreadState& ts, const Ray& ray, void* payload, bool occlusion) {
    TraceFrame& frame = ts.frames[ts.depth++];
    frame.world_ray = ray;
    frame.object_ray = ray;
    frame.payload = payload;
    frame.ray_type = ray.ray_type;
    frame.closest = ray.tmax;
    frame.has_hit = false;
    frame.terminated = false;
    frame.occlusion = occlusion;
    frame.transformed = false;
    frame.candidate_open = false;
    frame.to_world = frame.to_object = kIdentity;
    frame.context = ProgramContext::kIntersection;
    return frame;
}
}  // namespace

void trace(ThreadState& ts, Handle root, const Ray& ray, void* payload, const void* payload_tag) {
    const CompiledScene& scene = *ts.scene;
    if (ray.ray_type >= scene.ray_types.size())
        throw ProgramException{kExceptionInvalidRayType, ray.ray_type};
    if (payload_tag != scene.ray_types[ray.ray_type].payload->tag)
        throw ProgramException{kExceptionPayloadTypeMismatch, ray.ray_type};
    if (root.index >= scene.nodes.size())
        throw ProgramException{kExceptionInvalidHandle, root.index};
    if (ts.depth >= scene.max_depth) throw ProgramException{kExceptionStackOverflow, ts.depth + 1};

    TraceFrame& frame = push_frame(ts, ray, payload, /*occlusion=*/false);

    Traverser(ts, frame).node(root.index, ray.origin, ray.direction);

    if (frame.has_hit) {
        HitState& hit = frame.hit;
        const CompiledInstance& inst = scene.instances[hit.instance];
        if (hit.attributes_pending) {
            // The attribute program runs as at the hit: its primitive, transform and ray.
            frame.object_ray = ray;
            frame.instance = &inst;
            frame.instance_index = hit.instance;
            frame.prim = hit.prim;
            frame.transformed = hit.transformed;
            if (hit.transformed) {
                frame.to_world = hit.to_world;
                frame.to_object = hit.to_object;
                frame.object_ray.origin = transform_point(hit.to_object, ray.origin);
                frame.object_ray.direction = transform_vector(hit.to_object, ray.direction);
            }
            Traverser::compute_triangle_attributes(ts, inst, hit.prim, hit.barycentrics,
                                                   hit.attributes);
        }
        frame.object_ray = ray;
        const core::CompiledProgram& closest =
            inst.materials[hit.material].closest_hit[ray.ray_type];
        if (closest) {
            frame.context = ProgramContext::kClosestHit;
            closest.entry<HitFn>()(closest.rec(), payload, hit.attributes.bytes);
        }
    } else if (const core::CompiledProgram& miss = scene.miss[ray.ray_type]) {
        frame.context = ProgramContext::kMiss;
        miss.entry<MissFn>()(miss.rec(), payload);
    }
    --ts.depth;
}

bool occluded(ThreadState& ts, Handle root, const Ray& ray) {
    const CompiledScene& scene = *ts.scene;
    if (!scene.uses_occluded)  // the GPU's megakernel would not compile this call either
        throw Error("occluded() is called, but no module of this scene declares it; declare "
                    "it in the module that calls it: LUCENT_MODULE(name, lucent::kUsesOccluded)");
    if (ray.ray_type >= scene.ray_types.size())
        throw ProgramException{kExceptionInvalidRayType, ray.ray_type};
    if (root.index >= scene.nodes.size())
        throw ProgramException{kExceptionInvalidHandle, root.index};
    // A GeometryGroup of triangles (the common shadow root): the BVH's any-hit traversal.
    const CompiledNode& root_node = scene.nodes[root.index];
    if (root_node.kind == NodeKind::kGeometryGroup && root_node.geometry &&
        root_node.geometry->triangles_only)
        return root_node.geometry->triangles.occluded(ray.origin, ray.direction, ray.tmin,
                                                      ray.tmax);
    // Anything else needs a frame: intersection programs and selectors run in it.
    if (ts.depth >= scene.max_depth) throw ProgramException{kExceptionStackOverflow, ts.depth + 1};
    TraceFrame& frame = push_frame(ts, ray, nullptr, /*occlusion=*/true);
    Traverser(ts, frame).node(root.index, ray.origin, ray.direction);
    frame.occlusion = false;
    --ts.depth;
    return frame.has_hit;
}

}  // namespace lucent::cpu

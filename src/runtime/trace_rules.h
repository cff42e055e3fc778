// The trace state machine, written once for both backends (pbrt-v4's way: LUCENT_HD code
// instantiated by each backend): what each program kind may call and what it sees, how a
// candidate becomes the committed hit, how any-hit programs accept, ignore or terminate,
// the checks before a trace and the shade phase after traversal (OptiX paper §3.1, Fig. 2:
// Traverse, then Shade). The traversal itself (the CPU's over core::CompiledScene, the
// GPU's over its BVHs) stays with each backend and calls in here.
//
// A backend instantiates it with a policy object `p` (its methods const) that provides:
//   Thread, Instance, Program, PayloadTag      types; a Thread has the members
//                                              `Frame* frame`, `unsigned depth` and
//                                              `ProgramContext context` (outside any trace)
//   kTransforms, kOcclusion, kAttributeBytes   what frames hold and which paths exist
//   thread()                                   the calling thread's state
//   raise(code, detail)                        the CPU throws core::ProgramException; the
//   exception_pending()                        GPU records it and the caller returns
//   ray_type_count(), payload_matches(ray_type, tag), node_count(), max_depth(), no_ray()
//   instance(i), material_count(inst), primitive_material(inst, prim), triangle(inst, prim,
//   p0, p1, p2), any_hit(inst, material, ray_type), closest_hit(...), miss(ray_type),
//   attribute(inst), bound(program)            the scene, and which programs are bound
//   opaque(inst), visibility_mask(inst),
//   user_id(inst)                              a geometry instance's flags, mask and id
//   call_any_hit, call_closest_hit, call_miss, call_attribute, call_intersection,
//   call_visit                                 program dispatch
//   copy_attributes(dst, src, inst), traverse(frame, root, ray)
#pragma once

#include "lucent/device/api.h"
#include "lucent/device/curve_intersect.h"
#include "lucent/device/sphere_intersect.h"
#include "runtime/motion.h"
#include "runtime/trace_frame.h"

// The GPU's tuning: these run inside trace_ray's frame (inlined, as they were written
// there); g++ decides for itself on the CPU.
#if LUCENT_GPU_CODE
#define LUCENT_RUNTIME_INLINE LUCENT_HD __forceinline__
#else
#define LUCENT_RUNTIME_INLINE inline
#endif

namespace lucent::runtime {

template <class P>
using FrameOf = TraceFrame<P>;

// ---- what the running program sees ------------------------------------------------------

/// current_ray(): object space in intersection, any-hit, visit and attribute programs (the
/// space of the node being traversed), world space elsewhere; a zero ray outside a trace.
template <class P>
LUCENT_RUNTIME_INLINE const Ray& current_ray(const P& p) {
    const FrameOf<P>* f = p.thread().frame;
    if (!f) return p.no_ray();
    switch (f->context) {
        case ProgramContext::kIntersection:
        case ProgramContext::kAnyHit:
        case ProgramContext::kVisit:
        case ProgramContext::kAttribute:
            if constexpr (P::kTransforms)
                return f->object_ray;
            else
                return f->world_ray;  // no transforms: object space is world space
        default:
            return f->world_ray;
    }
}

/// t_hit(): the candidate's t in any-hit, the committed hit's in closest hit, tmax in miss,
/// the closest so far elsewhere in a trace; 0 outside one.
template <class P>
LUCENT_RUNTIME_INLINE float t_hit(const P& p) {
    const FrameOf<P>* f = p.thread().frame;
    if (!f) return 0.0f;
    switch (f->context) {
        case ProgramContext::kAnyHit:
            return f->candidate_t;
        case ProgramContext::kClosestHit:
            return f->hit_t;
        case ProgramContext::kMiss:
            return f->world_ray.tmax;
        default:
            return f->closest;
    }
}

/// instance_id(): the innermost Transform's user id, of the committed hit in closest hit and
/// of the traversal position in the programs that run during traversal; 0 elsewhere.
template <class P>
LUCENT_RUNTIME_INLINE unsigned instance_id(const P& p) {
    if constexpr (P::kTransforms) {
        const FrameOf<P>* f = p.thread().frame;
        if (!f || f->context == ProgramContext::kMiss) return 0;
        return f->context == ProgramContext::kClosestHit ? f->hit_instance_id : f->instance_id;
    } else {
        (void)p;
        return 0;
    }
}

/// geometry_instance_id(): the user id of the committed hit's GeometryInstance in closest
/// hit, of the one being intersected in intersection, any-hit and attribute programs.
template <class P>
LUCENT_RUNTIME_INLINE unsigned geometry_instance_id(const P& p) {
    const FrameOf<P>* f = p.thread().frame;
    if (!f) return 0;
    switch (f->context) {
        case ProgramContext::kClosestHit:
            return p.user_id(p.instance(f->hit_instance));
        case ProgramContext::kIntersection:
        case ProgramContext::kAnyHit:
        case ProgramContext::kAttribute:
            return p.user_id(p.instance(f->instance));
        default:
            return 0;
    }
}

/// primitive_index(): the committed hit's in closest hit, the traversal position's elsewhere.
template <class P>
LUCENT_RUNTIME_INLINE unsigned primitive_index(const P& p) {
    const FrameOf<P>* f = p.thread().frame;
    if (!f) return 0;
    return f->context == ProgramContext::kClosestHit ? f->hit_prim : f->prim;
}

/// The transform of the committed hit in closest hit, of the traversal position in the
/// programs that run during traversal; none in miss, outside a trace, or when not below a
/// Transform.
template <class P>
LUCENT_RUNTIME_INLINE bool current_transform(const P& p, const Matrix4x3*& to_world,
                                             const Matrix4x3*& to_object) {
    if constexpr (P::kTransforms) {
        const FrameOf<P>* f = p.thread().frame;
        if (!f) return false;
        if (f->context == ProgramContext::kClosestHit) {
            if (!f->hit_transformed) return false;
            to_world = &f->hit_to_world;
            to_object = &f->hit_to_object;
            return true;
        }
        if (f->context == ProgramContext::kMiss || !f->transformed) return false;
        to_world = &f->to_world;
        to_object = &f->to_object;
        return true;
    } else {
        (void)p;
        (void)to_world;
        (void)to_object;
        return false;
    }
}

// ---- transforms and spaces during traversal -------------------------------------------------

/// a ∘ b for affine matrices (apply b first).
LUCENT_HD inline Matrix4x3 compose(const Matrix4x3& a, const Matrix4x3& b) {
    Matrix4x3 r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j) {
            float v =
                a.m[i * 4 + 0] * b.m[j] + a.m[i * 4 + 1] * b.m[4 + j] + a.m[i * 4 + 2] * b.m[8 + j];
            r.m[i * 4 + j] = j == 3 ? v + a.m[i * 4 + 3] : v;
        }
    return r;
}

/// The traversal position's transform before a Transform node was entered.
struct SavedTransform {
    bool transformed;
    unsigned instance_id;
    Matrix4x3 to_world, to_object;
};

/// Enters a Transform node (user id `instance_id`). Rays enter the child's space; the
/// direction is not renormalised, so t is the same in every space and hits compare across
/// transforms.
template <class Frame>
LUCENT_RUNTIME_INLINE SavedTransform enter_transform(Frame& f, const Matrix4x3& to_world,
                                                     const Matrix4x3& to_object,
                                                     unsigned instance_id) {
    const SavedTransform saved{f.transformed, f.instance_id, f.to_world, f.to_object};
    f.to_world = saved.transformed ? compose(saved.to_world, to_world) : to_world;
    f.to_object = saved.transformed ? compose(to_object, saved.to_object) : to_object;
    f.transformed = true;
    if constexpr (Frame::kRayControl) f.instance_id = instance_id;
    return saved;
}
template <class Frame>
LUCENT_RUNTIME_INLINE void leave_transform(Frame& f, const SavedTransform& saved) {
    f.transformed = saved.transformed;
    if constexpr (Frame::kRayControl) f.instance_id = saved.instance_id;
    f.to_world = saved.to_world;
    f.to_object = saved.to_object;
}

// ---- ray flags and visibility masks (OptiX 7's OptixRayFlags and visibilityMask) ---------------

/// Does a node or instance with visibility mask `mask` take part in this trace?
template <class Frame>
LUCENT_HD inline bool visible(const Frame& f, unsigned mask) {
    if constexpr (!Frame::kRayControl) {  // every mask is 0xff
        (void)f;
        (void)mask;
        return true;
    }
    return (mask & f.ray_mask) != 0;
}

/// Is a primitive of `inst` opaque for this ray (its any-hit programs do not run)? The ray's
/// kRayFlagDisableAnyHit and kRayFlagEnforceAnyHit override the geometry's flag.
template <class P>
LUCENT_HD inline bool opaque_for_ray(const P& p, const FrameOf<P>& f,
                                     const typename P::Instance& inst) {
    if constexpr (!P::kRayControl) return false;  // no geometry is opaque
    if (f.ray_flags & kRayFlagDisableAnyHit) return true;
    if (f.ray_flags & kRayFlagEnforceAnyHit) return false;
    return p.opaque(inst);
}

/// kRayFlagCullDisabledAnyHit skips opaque primitives, kRayFlagCullEnforcedAnyHit the others.
template <class Frame>
LUCENT_HD inline bool culled_by_opacity(const Frame& f, bool opaque) {
    return f.ray_flags & (opaque ? kRayFlagCullDisabledAnyHit : kRayFlagCullEnforcedAnyHit);
}

/// The facing culls, for a triangle candidate: front-facing when the ray, in the triangle's
/// object space, runs against cross(p1 - p0, p2 - p0) (counter-clockwise from its origin).
template <class P>
LUCENT_HD inline bool culled_by_facing(const P& p, const FrameOf<P>& f,
                                       const typename P::Instance& inst, unsigned prim) {
    float3 p0, p1, p2;
    p.triangle(inst, prim, p0, p1, p2);
    float3 direction;
    if constexpr (P::kTransforms)
        direction = f.object_ray.direction;
    else
        direction = f.world_ray.direction;
    const bool front = dot(cross(p1 - p0, p2 - p0), direction) < 0.0f;
    return f.ray_flags &
           (front ? kRayFlagCullFrontFacingTriangles : kRayFlagCullBackFacingTriangles);
}

/// Culls that need each candidate: a trace with one of them cannot take a fast path that
/// only returns the closest hit.
constexpr unsigned kRayFlagsPerCandidate = kRayFlagsFacingCull | kRayFlagCullDisabledAnyHit |
                                           kRayFlagCullEnforcedAnyHit |
                                           kRayFlagTerminateOnFirstHit;

/// Flags that do not contradict each other, and an 8-bit mask.
LUCENT_HD inline bool ray_flags_valid(unsigned flags, unsigned mask) {
    const unsigned choice = flags & kRayFlagsAnyHitChoice, facing = flags & kRayFlagsFacingCull;
    return !(flags & ~kRayFlagsAll) && mask <= kVisibilityMaskAll &&
           (choice & (choice - 1)) == 0 && (facing & (facing - 1)) == 0;
}

/// What occluded() accepts: no any-hit flag but kRayFlagDisableAnyHit (it runs no any-hit),
/// and no facing cull with leaf boxes (they load no triangle).
LUCENT_HD inline bool occlusion_flags_valid(unsigned flags, unsigned mask, bool leaf_boxes) {
    const unsigned any_hit_flags =
        kRayFlagEnforceAnyHit | kRayFlagCullDisabledAnyHit | kRayFlagCullEnforcedAnyHit;
    return ray_flags_valid(flags, mask) && !(flags & any_hit_flags) &&
           !(leaf_boxes && (flags & kRayFlagsFacingCull));
}

/// The detail of kExceptionInvalidRayFlags.
LUCENT_HD inline unsigned ray_flags_detail(unsigned flags, unsigned mask) {
    return mask << 16 | (flags & 0xffffu);
}

/// The ray the programs of a node see: the world ray's interval, in the node's space.
template <class P>
LUCENT_RUNTIME_INLINE void enter_space(FrameOf<P>& f, float3 origin, float3 direction) {
    if constexpr (P::kTransforms) {  // else the object-space ray is the world ray
        f.object_ray.origin = origin;
        f.object_ray.direction = direction;
    } else {
        (void)f;
        (void)origin;
        (void)direction;
    }
}

// ---- programs run during traversal -----------------------------------------------------------

/// A Selector's visit program, in the selector's space: the child to traverse.
template <class P>
LUCENT_RUNTIME_INLINE unsigned run_visit(const P& p, FrameOf<P>& f, typename P::Program visit,
                                         float3 origin, float3 direction) {
    enter_space<P>(f, origin, direction);
    const ProgramContext saved = f.context;
    f.context = ProgramContext::kVisit;
    const unsigned child = p.call_visit(visit);
    f.context = saved;
    return child;
}

/// A custom primitive's intersection program; it reports through potential_intersection
/// and report_intersection.
template <class P>
LUCENT_RUNTIME_INLINE void run_intersection(const P& p, FrameOf<P>& f, unsigned instance_index,
                                            const typename P::Instance& inst, unsigned prim) {
    if (f.masked_instances && !visible(f, p.visibility_mask(inst))) return;
    f.instance = instance_index;
    f.prim = prim;
    const ProgramContext saved = f.context;
    f.context = ProgramContext::kIntersection;
    p.call_intersection(inst, prim, f.scratch.bytes);
    f.context = saved;
}

/// The attributes of a triangle hit: the attribute program's, or the built-in
/// TriangleAttributes (barycentrics and object-space geometric normal).
/// The attributes of built-in triangles without an attribute program (TriangleAttributes),
/// from the triangle's vertices: the one formula every backend and path uses.
template <class Attributes>
LUCENT_HD inline void builtin_triangle_attributes(float2 bary, float3 p0, float3 p1, float3 p2,
                                                  Attributes& out) {
#if LUCENT_GPU_CODE
    TriangleAttributes* a = reinterpret_cast<TriangleAttributes*>(out.bytes);
    a->barycentrics = bary;
    a->geometric_normal = normalize(cross(p1 - p0, p2 - p0));
#else
    // Each member straight from its registers: built in a local and copied whole, the
    // copy's wide load would span the local's narrower stores (a store-forwarding stall).
    const float3 n = normalize(cross(p1 - p0, p2 - p0));
    __builtin_memcpy(out.bytes + offsetof(TriangleAttributes, barycentrics), &bary, sizeof bary);
    __builtin_memcpy(out.bytes + offsetof(TriangleAttributes, geometric_normal), &n, sizeof n);
#endif
}

template <class P>
LUCENT_HD inline void triangle_attributes(const P& p, FrameOf<P>& f,
                                          const typename P::Instance& inst, unsigned prim,
                                          float2 bary, typename FrameOf<P>::Attributes& out) {
    const typename P::Program attribute = p.attribute(inst);
    if (p.bound(attribute)) {
        const ProgramContext saved = f.context;
        f.context = ProgramContext::kAttribute;
        p.call_attribute(attribute, prim, bary, out.bytes);
        f.context = saved;
        return;
    }
    float3 p0, p1, p2;
    p.triangle(inst, prim, p0, p1, p2);
    builtin_triangle_attributes(bary, p0, p1, p2, out);
}

/// Records a hit as the closest so far (the caller fills its attributes).
template <class P>
LUCENT_HD inline void commit(FrameOf<P>& f, unsigned instance, unsigned prim, float t,
                             unsigned material) {
    f.has_hit = true;
    f.closest = t;
    f.hit_t = t;
    f.hit_instance = instance;
    f.hit_prim = prim;
    f.hit_material = material;
    f.hit_pending = false;
    if constexpr (P::kTransforms) {
        f.hit_transformed = f.transformed;
        if constexpr (P::kRayControl) f.hit_instance_id = f.instance_id;
        if (f.transformed) {
            f.hit_to_world = f.to_world;
            f.hit_to_object = f.to_object;
        }
    }
}

/// Commits a triangle hit whose attributes wait for the shade phase (no any-hit ran).
template <class P>
LUCENT_HD inline void commit_triangle(FrameOf<P>& f, unsigned instance, unsigned prim, float t,
                                      unsigned material, float2 bary) {
    commit<P>(f, instance, prim, t, material);
    f.hit_bary = bary;
    f.hit_pending = true;
}

/// Runs an any-hit program on the candidate (attributes in the scratch); false when it
/// ended with ignore_intersection(). terminate_ray() accepts the candidate and ends the
/// traversal.
template <class P>
LUCENT_HD inline bool run_any_hit(const P& p, FrameOf<P>& f, typename P::Program any) {
    const ProgramContext saved = f.context;
    f.context = ProgramContext::kAnyHit;
    f.any_hit = AnyHitOutcome::kAccept;
    p.call_any_hit(any, f.payload, f.scratch.bytes);
    f.context = saved;
    if (f.any_hit == AnyHitOutcome::kIgnore) return false;
    if (f.any_hit == AnyHitOutcome::kTerminate) f.terminated = true;
    return true;
}

/// In occluded(), any accepted intersection answers the query: it ends traversal.
template <class P>
LUCENT_HD inline bool answers_occlusion(FrameOf<P>& f) {
    if constexpr (P::kOcclusion) {
        if (f.occlusion) {
            f.has_hit = f.terminated = true;
            return true;
        }
    }
    return false;
}

/// A triangle hit nearer than the closest so far: the instance's mask and the ray's culls,
/// any-hit (unless opaque), then commit. True if accepted.
template <class P>
LUCENT_HD inline bool triangle_candidate(const P& p, FrameOf<P>& f, unsigned instance_index,
                                         unsigned prim, float t, float2 bary) {
    const typename P::Instance& inst = p.instance(instance_index);
    // Loads of the instance's mask and flags only for the rays and groups that need them:
    // the generic path would pay one per candidate (IGI's box graph: 4 % of its frame rate).
    if (f.masked_instances && !visible(f, p.visibility_mask(inst))) return false;
    if (f.ray_flags & kRayFlagsPerCandidate) {
        if ((f.ray_flags & kRayFlagsFacingCull) && culled_by_facing(p, f, inst, prim))
            return false;
        if (culled_by_opacity(f, opaque_for_ray(p, f, inst))) return false;
    }
    if (answers_occlusion<P>(f)) return true;
    const unsigned material = p.primitive_material(inst, prim);
    const typename P::Program any = p.any_hit(inst, material, f.ray_type);
    if (p.bound(any) && !opaque_for_ray(p, f, inst)) {
        f.instance = instance_index;
        f.prim = prim;
        triangle_attributes(p, f, inst, prim, bary, f.scratch);
        f.candidate_t = t;
        if (!run_any_hit(p, f, any)) return false;
        commit<P>(f, instance_index, prim, t, material);
        p.copy_attributes(f.hit_attr, f.scratch, inst);
    } else {
        commit_triangle<P>(f, instance_index, prim, t, material, bary);
    }
    if (f.ray_flags & kRayFlagTerminateOnFirstHit) f.terminated = true;
    return true;
}

/// Writes a built-in primitive's attributes into a frame's attribute bytes.
template <class Storage, class A>
LUCENT_HD inline void store_attributes(Storage& out, const A& attributes) {
    static_assert(sizeof(A) <= sizeof(out.bytes), "attributes larger than the frame holds");
#if LUCENT_GPU_CODE
    *reinterpret_cast<A*>(out.bytes) = attributes;
#else
    __builtin_memcpy(out.bytes, &attributes, sizeof attributes);
#endif
}

/// A hit of a built-in primitive other than a triangle (a sphere) at t, inside the ray's
/// interval, with the attributes its intersection computed: the instance's mask and the
/// ray's opacity culls, any-hit (unless opaque), then commit. True if accepted. The facing
/// culls are for triangles only, as in OptiX.
template <class P, class A>
LUCENT_HD inline bool primitive_candidate(const P& p, FrameOf<P>& f, unsigned instance_index,
                                          unsigned prim, float t, const A& attributes) {
    const typename P::Instance& inst = p.instance(instance_index);
    if (f.masked_instances && !visible(f, p.visibility_mask(inst))) return false;
    if ((f.ray_flags & (kRayFlagCullDisabledAnyHit | kRayFlagCullEnforcedAnyHit)) &&
        culled_by_opacity(f, opaque_for_ray(p, f, inst)))
        return false;
    if (answers_occlusion<P>(f)) return true;
    const unsigned material = p.primitive_material(inst, prim);
    const typename P::Program any = p.any_hit(inst, material, f.ray_type);
    if (p.bound(any) && !opaque_for_ray(p, f, inst)) {
        f.instance = instance_index;
        f.prim = prim;
        store_attributes(f.scratch, attributes);
        f.candidate_t = t;
        if (!run_any_hit(p, f, any)) return false;
    }
    commit<P>(f, instance_index, prim, t, material);
    store_attributes(f.hit_attr, attributes);
    if (f.ray_flags & kRayFlagTerminateOnFirstHit) f.terminated = true;
    return true;
}

/// A built-in sphere: both of its intersections inside the ray's interval, nearer first (a
/// ray from inside, or one whose any-hit ignored the near side, gets the far side).
template <class P>
LUCENT_HD inline void sphere_candidates(const P& p, FrameOf<P>& f, unsigned instance_index,
                                        unsigned prim, float3 origin, float3 direction,
                                        float3 center, float radius) {
    float t0, t1;
    if (!intersect_sphere(origin, direction, center, radius, t0, t1)) return;
    const float tmin = f.world_ray.tmin;
    for (int side = 0; side < 2; ++side) {
        const float t = side == 0 ? t0 : t1;
        if (!(t > tmin && t < f.closest)) continue;
        BuiltinSphereAttributes a;
        // The hit's offset from the centre, divided by the radius first (a tiny sphere's
        // squared offset would underflow), then made unit length against rounding.
        a.normal = (origin - center + t * direction) * (1.0f / radius);
        a.normal = a.normal * (1.0f / length(a.normal));
        a.entering = side == 0 ? 1u : 0u;
        if (primitive_candidate(p, f, instance_index, prim, t, a) || f.terminated) return;
    }
}

/// BVH reference `local` of a built-in curve instance (curve_references(curve_type) per
/// segment, each over its range of u): entries and exits inside the ray's interval, nearer
/// first, until one is accepted (a ray from inside the tube gets its exit). A part's exit is
/// searched only when its entry is refused or lies before the interval: an accepted entry
/// ends the search, every later candidate lying beyond it. The primitive is the segment.
template <class P>
LUCENT_HD inline void curve_candidates(const P& p, FrameOf<P>& f, unsigned instance_index,
                                       unsigned local, float3 origin, float3 direction,
                                       unsigned curve_type, const float3* vertices,
                                       const float* radii, const unsigned* segments) {
    const unsigned references = curve_references(curve_type);
    const unsigned prim = local / references, reference = local - prim * references;
    CurvePoint bezier[4];
    load_curve_segment(curve_type, vertices, radii, segments[prim], bezier);
    CurveParts q;
    const int parts = find_curve_parts(origin, direction, curve_type, bezier, reference,
                                       f.world_ray.tmin, f.closest, q);
    if (parts == 0) return;
    // Offers one hit; true when the search is over (accepted, or the trace terminated).
    const auto offer = [&](const CurveHit& hit) {
        if (!(hit.t < f.closest)) return false;
        BuiltinCurveAttributes a;
        a.normal = hit.normal;
        a.u = hit.u;
        a.entering = hit.entering;
        return primitive_candidate(p, f, instance_index, prim, hit.t, a) || f.terminated;
    };
    const int first = parts == 2 && q.part[1].s_in < q.part[0].s_in ? 1 : 0;
    CurveHit exits[2];
    int pending = 0;  // exits found, nearest first
    for (int k = 0; k < parts; ++k) {
        const int i = k == 0 ? first : 1 - first;
        const float entry_t = q.part[i].s_in / q.speed;
        // Exits of earlier parts that come before this entry.
        while (pending > 0 && exits[0].t < entry_t) {
            if (offer(exits[0])) return;
            exits[0] = exits[1];
            --pending;
        }
        CurveHit hit;
        if (curve_part_hit(q, i, 0, f.world_ray.tmin, f.closest, hit) && offer(hit)) return;
        if (curve_part_hit(q, i, 1, f.world_ray.tmin, f.closest, hit)) {
            int j = pending++;
            for (; j > 0 && exits[j - 1].t > hit.t; --j) exits[j] = exits[j - 1];
            exits[j] = hit;
        }
    }
    for (int k = 0; k < pending; ++k)
        if (offer(exits[k])) return;
}

// ---- the device API of intersection and any-hit programs --------------------------------------

/// potential_intersection(t), in an intersection program: is t inside the ray's current
/// interval (tmin, closest)? Elsewhere false.
/// The context, tmin and closest are read together and combined without a branch: on the
/// GPU the frame is in local memory, and a branch on the context before the other two reads
/// put a second memory round trip on every intersection test (Whitted 4 % slower). Outside
/// an intersection program nothing opens, and candidate_open, which only
/// report_intersection reads, is cleared.
template <class P>
LUCENT_RUNTIME_INLINE bool potential_intersection(const P& p, float t) {
    FrameOf<P>* f = p.thread().frame;
    if (!f) return false;
    const bool open = (f->context == ProgramContext::kIntersection) &
                      (t > f->world_ray.tmin) & (t < f->closest);
    f->candidate_open = open;
    if (open) f->candidate_t = t;
    return open;
}

/// report_intersection(material), in an intersection program after potential_intersection
/// returned true: any-hit, then commit with the attributes the program wrote. False when
/// any-hit ignored it, when no potential intersection is open, or outside an intersection
/// program. A material index beyond the instance's raises kExceptionMaterialIndexOutOfRange.
template <class P>
LUCENT_RUNTIME_INLINE bool report_intersection(const P& p, unsigned material) {
    FrameOf<P>* f = p.thread().frame;
    if (!f || f->context != ProgramContext::kIntersection || !f->candidate_open) return false;
    f->candidate_open = false;
    const typename P::Instance& inst = p.instance(f->instance);
    if (material >= p.material_count(inst)) {
        p.raise(kExceptionMaterialIndexOutOfRange, material);
        return false;
    }
    if (answers_occlusion<P>(*f)) return true;  // occluded(): no any-hit runs
    if ((f->ray_flags & (kRayFlagCullDisabledAnyHit | kRayFlagCullEnforcedAnyHit)) &&
        culled_by_opacity(*f, opaque_for_ray(p, *f, inst)))
        return false;
    const typename P::Program any = p.any_hit(inst, material, f->ray_type);
    if (p.bound(any) && !opaque_for_ray(p, *f, inst) && !run_any_hit(p, *f, any)) return false;
    commit<P>(*f, f->instance, f->prim, f->candidate_t, material);
    p.copy_attributes(f->hit_attr, f->scratch, inst);
    if (f->ray_flags & kRayFlagTerminateOnFirstHit) f->terminated = true;
    return true;
}

/// What ignore_intersection() and terminate_ray() leave for run_any_hit (the macros then
/// return from the program). They compile only in an any-hit body, and only run_any_hit
/// reads the outcome, after resetting it for each program it runs: no context check is
/// needed (an any-hit function called by hand from another program changes nothing).
template <class P>
LUCENT_RUNTIME_INLINE void end_any_hit(const P& p, AnyHitOutcome outcome) {
    FrameOf<P>* f = p.thread().frame;
    if (f) f->any_hit = outcome;
}

// ---- trace() and occluded() ------------------------------------------------------------------

/// The checks before a trace, each raising its exception: ray type, payload type, ray
/// flags and mask, root handle, depth.
template <class P>
LUCENT_RUNTIME_INLINE bool trace_allowed(const P& p, Handle root, const Ray& ray,
                                         typename P::PayloadTag payload_tag, unsigned ray_flags,
                                         unsigned ray_mask) {
    if (!ray_flags_valid(ray_flags, ray_mask)) {
        p.raise(kExceptionInvalidRayFlags, ray_flags_detail(ray_flags, ray_mask));
        return false;
    }
    if (ray.ray_type >= p.ray_type_count()) {
        p.raise(kExceptionInvalidRayType, ray.ray_type);
        return false;
    }
    if (!p.payload_matches(ray.ray_type, payload_tag)) {
        p.raise(kExceptionPayloadTypeMismatch, ray.ray_type);
        return false;
    }
    if (root.index >= p.node_count()) {
        p.raise(kExceptionInvalidHandle, root.index);
        return false;
    }
    if (p.thread().depth >= p.max_depth()) {
        p.raise(kExceptionStackOverflow, p.thread().depth + 1);
        return false;
    }
    return true;
}

/// A trace frame for `ray`, before traversal.
template <class P>
LUCENT_RUNTIME_INLINE void begin_frame(FrameOf<P>& f, const Ray& ray, void* payload,
                                       bool occlusion, unsigned ray_flags, unsigned ray_mask) {
    f.world_ray = ray;
    if constexpr (P::kTransforms) {
        f.object_ray = ray;
        f.transformed = false;
    }
    f.payload = payload;
    f.ray_type = ray.ray_type;
    if constexpr (P::kRayControl) {
        f.ray_flags = ray_flags;
        f.ray_mask = ray_mask;
        f.masked_instances = false;
        if constexpr (P::kTransforms) f.instance_id = 0;
    } else {  // ray_allowed refused anything else
        (void)ray_flags;
        (void)ray_mask;
    }
    f.closest = ray.tmax;
    f.has_hit = false;
    f.terminated = false;
    f.occlusion = occlusion;
    f.leaf_boxes = false;
    f.candidate_open = false;
    f.context = ProgramContext::kIntersection;
}

/// The closest-hit program of the committed hit, if one is bound and not disabled, with
/// the hit's attributes.
template <class P>
LUCENT_RUNTIME_INLINE void run_closest_hit(const P& p, FrameOf<P>& f,
                                           const typename P::Instance& inst, const Ray& ray,
                                           const typename FrameOf<P>::Attributes& attributes) {
    if constexpr (P::kTransforms) f.object_ray = ray;
    const typename P::Program closest = p.closest_hit(inst, f.hit_material, f.ray_type);
    if (p.bound(closest) && !(f.ray_flags & kRayFlagDisableClosestHit)) {
        f.context = ProgramContext::kClosestHit;
        p.call_closest_hit(closest, f.payload, attributes.bytes);
    }
}

/// After traversal: the attributes of a pending triangle hit, then closest hit or miss.
template <class P>
LUCENT_RUNTIME_INLINE void shade(const P& p, FrameOf<P>& f, const Ray& ray) {
    if (f.has_hit) {
        const typename P::Instance& inst = p.instance(f.hit_instance);
        if (!f.hit_pending) {
            run_closest_hit(p, f, inst, ray, f.hit_attr);
            return;
        }
        // The attribute program runs as at the hit: its primitive, transform and ray.
        f.instance = f.hit_instance;
        f.prim = f.hit_prim;
        if constexpr (P::kTransforms) {
            f.object_ray = ray;
            f.transformed = f.hit_transformed;
            if (f.hit_transformed) {
                f.to_world = f.hit_to_world;
                f.to_object = f.hit_to_object;
                f.object_ray.origin = transform_point(f.hit_to_object, ray.origin);
                f.object_ray.direction = transform_vector(f.hit_to_object, ray.direction);
            }
        }
        // In a local, not in the frame (which the thread state points at): where the
        // closest-hit program is inlined and never reads its attributes (a program that
        // needs only t_hit() and primitive_index()), the compiler drops their computation,
        // the triangle's index and vertex loads included.
        typename FrameOf<P>::Attributes attributes;
        triangle_attributes(p, f, inst, f.hit_prim, f.hit_bary, attributes);
        run_closest_hit(p, f, inst, ray, attributes);
    } else {
        const typename P::Program miss = p.miss(f.ray_type);
        if (p.bound(miss)) {
            f.context = ProgramContext::kMiss;
            p.call_miss(miss, f.payload);
        }
    }
}

/// trace(): the checks, a frame on this function's stack, traversal, then shade. On the
/// GPU a recorded exception ends the launch index's work: later traces return at once.
template <class P>
LUCENT_RUNTIME_INLINE void trace(const P& p, Handle root, const Ray& ray, void* payload,
                                 typename P::PayloadTag payload_tag, unsigned ray_flags,
                                 unsigned ray_mask) {
    typename P::Thread& s = p.thread();
    if (p.exception_pending()) return;
    if (!trace_allowed(p, root, ray, payload_tag, ray_flags, ray_mask)) return;
    FrameOf<P> f;
    begin_frame<P>(f, ray, payload, /*occlusion=*/false, ray_flags, ray_mask);
    FrameOf<P>* outer = s.frame;
    s.frame = &f;
    ++s.depth;
    p.traverse(f, root, ray);
    if (!p.exception_pending()) shade(p, f, ray);
    --s.depth;
    s.frame = outer;
}

/// The checks of occluded() that come before any fast path: ray flags and mask, ray type
/// and root handle.
template <class P>
LUCENT_RUNTIME_INLINE bool occlusion_allowed(const P& p, Handle root, const Ray& ray,
                                             bool leaf_boxes, unsigned ray_flags,
                                             unsigned ray_mask) {
    if (!occlusion_flags_valid(ray_flags, ray_mask, leaf_boxes)) {
        p.raise(kExceptionInvalidRayFlags, ray_flags_detail(ray_flags, ray_mask));
        return false;
    }
    if (ray.ray_type >= p.ray_type_count()) {
        p.raise(kExceptionInvalidRayType, ray.ray_type);
        return false;
    }
    if (root.index >= p.node_count()) {
        p.raise(kExceptionInvalidHandle, root.index);
        return false;
    }
    return true;
}

/// occluded() through an occlusion frame (intersection programs and selectors run in it,
/// any-hit, closest hit and miss do not): any graph, after occlusion_allowed. With
/// `leaf_boxes`, triangle groups answer by their BVH's leaf boxes (Occlusion::kLeafBoxes).
template <class P>
LUCENT_RUNTIME_INLINE bool occluded_in_frame(const P& p, Handle root, const Ray& ray,
                                             bool leaf_boxes, unsigned ray_flags,
                                             unsigned ray_mask) {
    typename P::Thread& s = p.thread();
    if (s.depth >= p.max_depth()) {
        p.raise(kExceptionStackOverflow, s.depth + 1);
        return false;
    }
    FrameOf<P> f;
    begin_frame<P>(f, ray, nullptr, /*occlusion=*/true, ray_flags, ray_mask);
    f.leaf_boxes = leaf_boxes;
    FrameOf<P>* outer = s.frame;
    s.frame = &f;
    ++s.depth;
    p.traverse(f, root, ray);
    --s.depth;
    s.frame = outer;
    return f.has_hit && !p.exception_pending();
}

}  // namespace lucent::runtime

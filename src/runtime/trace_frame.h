// The state of one trace, shared by the CPU backend (compiled by g++) and the megakernel
// (compiled by NVRTC): which program is running, the ray in world and object space, the
// closest hit so far and the traversal position. A backend's policy (trace_rules.h) says
// whether frames carry transforms and how many attribute bytes they hold.
#pragma once

#include "lucent/device/api.h"
#include "lucent/device/types.h"
#include "lucent/device/vector_math.h"

namespace lucent::runtime {

/// The kind of program that is running: the device API's rules depend on it.
enum class ProgramContext : unsigned {
    kRayGeneration,
    kException,
    kMiss,
    kClosestHit,
    kAnyHit,
    kIntersection,
    kVisit,
    kAttribute,
    kBoundingBox,
};

/// How an any-hit program ended: by returning (the candidate is accepted), or by
/// ignore_intersection() or terminate_ray().
using detail::AnyHitOutcome;

template <unsigned Bytes>
struct alignas(16) AttributeBytes {
    unsigned char bytes[Bytes];
};

/// The transform part of a frame: the traversal position's and the committed hit's. Scenes
/// without Transforms (a megakernel generated for one) have none of it.
template <bool Transforms>
struct FrameTransforms {
    Ray object_ray;  // in the space of the node being traversed
    bool transformed, hit_transformed;
    Matrix4x3 to_world, to_object, hit_to_world, hit_to_object;
};
template <>
struct FrameTransforms<false> {};

/// The per-ray control part of a frame (ray flags, visibility masks, instance ids). A
/// megakernel whose scene and modules use none of it has constants instead, so every test
/// of them folds away (the frame lives in GPU local memory: Whitted was 8 % slower with
/// the fields).
template <bool RayControl>
struct FrameRayControl {
    unsigned ray_flags;  // RayFlags of trace() or occluded()
    unsigned ray_mask;   // the ray's visibility mask
    // The GeometryGroup being traversed has instances whose visibility mask is not 0xff:
    // candidates check their instance's mask (set by the traversal on entering a group).
    bool masked_instances;
    unsigned instance_id, hit_instance_id;  // of the innermost Transform (instance_id())
};
template <>
struct FrameRayControl<false> {
    static constexpr unsigned ray_flags = kRayFlagNone;
    static constexpr unsigned ray_mask = kVisibilityMaskAll;
    static constexpr bool masked_instances = false;
    static constexpr unsigned instance_id = 0, hit_instance_id = 0;
};

/// One active trace; it lives on the stack of the trace that owns it (recursion nests
/// them) and the thread state points at the innermost. Fields are set by begin_frame, not
/// by initialisers: the GPU would otherwise clear them on every trace.
template <class Policy>
struct TraceFrame : FrameTransforms<Policy::kTransforms>, FrameRayControl<Policy::kRayControl> {
    using Attributes = AttributeBytes<Policy::kAttributeBytes>;
    static constexpr bool kRayControl = Policy::kRayControl;
    Ray world_ray;  // as passed to trace()
    void* payload;
    unsigned ray_type;
    float closest;  // upper end of the ray interval: shrinks with each committed hit
    ProgramContext context;
    bool has_hit, terminated, candidate_open;
    bool occlusion;   // occluded(): the first intersection ends it, no programs run
    bool leaf_boxes;  // occluded(..., Occlusion::kLeafBoxes): triangles by their leaf boxes
    AnyHitOutcome any_hit;
    // the committed (closest so far) hit
    float hit_t;
    unsigned hit_instance, hit_prim, hit_material;
    float2 hit_bary;
    bool hit_pending;  // triangles: attributes computed at shade time
    // the traversal position, and the candidate of the intersection program being run
    unsigned instance, prim;
    float candidate_t;
    Attributes hit_attr;
    Attributes scratch;
};

}  // namespace lucent::runtime

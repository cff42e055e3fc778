// The compiled scene as the megakernel sees it: flat arrays in device memory, indexed by
// integers. Shared by the host (which fills it, src/cuda/backend/gpu_scene.cpp) and the device.
#pragma once

#include "lucent/device/types.h"
#include "runtime/motion.h"
#include "lucent_gpu/triangle_bvh.cuh"

namespace lucent::gpu {

/// A bound program: its id in the generated dispatch (< 0: none) and its record's offset
/// in the record blob.
struct ProgramRef {
    int id;
    unsigned record;
};

enum GpuNodeKind : unsigned {
    kGpuGroup = 0,
    kGpuGeometryGroup = 1,
    kGpuTransform = 2,
    kGpuSelector = 3
};

struct GpuNode {
    unsigned kind;
    unsigned first;  // children[first .. first + count) for Group, Selector, Transform
    unsigned count;
    unsigned accel;  // Group: bvhs index (~0u: brute force); GeometryGroup: accels index
    unsigned visibility_mask;
    unsigned instance_id;  // Transform: its user id (instance_id())
    ProgramRef visit;
    Matrix4x3 to_world, to_object;
    runtime::MotionRange motion;  // Transform: keys in LaunchParams::motion, or kMotionNone
};

/// Binary BVH node, the layout of lucent::accel::BvhNode.
struct GpuBvhNode {
    float3 lo;
    unsigned first;
    float3 hi;
    unsigned count;
};

struct GpuBvh {
    unsigned node_offset;  // into bvh_nodes; ~0u when empty
    unsigned prim_offset;  // into prim_order (and, for a GeometryGroup, prim_refs)
};

/// A GeometryGroup's primitive in the order its BVH's leaves hold them, already resolved:
/// the instance (index into LaunchParams::instances) and the primitive within it. Saves the
/// generic traversal a search of the accel's instances and two dependent loads per
/// primitive it visits.
struct GpuPrimRef {
    unsigned instance;
    unsigned prim;
};

struct GpuGeometryAccel {
    unsigned triangles_only;
    unsigned brute_force;
    unsigned any_hit_mask;     // bit r: some non-opaque instance has an any-hit for ray type r
    unsigned any_hit_enforced_mask;  // bit r: some instance has one (kRayFlagEnforceAnyHit)
    unsigned instances_masked;       // some instance's visibility mask is not 0xff
    unsigned instance_offset;  // accel_instances[instance_offset + k]: CompiledInstance index
    unsigned instance_count;
    unsigned prim_first_offset;  // accel_prim_first[...]: first global primitive per instance
    unsigned prim_total;
    GpuBvh bvh;                    // generic path
    GpuTriangleBvhView triangles;  // triangles_only path (triangle ids are global primitives)
};

/// GpuInstance::type: lucent::PrimitiveType's values.
enum GpuPrimitiveType : unsigned {
    kGpuCustom = 0,
    kGpuTriangles = 1,
    kGpuSpheres = 2,
    kGpuCurves = 3,
};

struct GpuInstance {
    unsigned type;  // GpuPrimitiveType
    unsigned prim_count;
    unsigned opaque;  // kGeometryFlagDisableAnyHit
    unsigned visibility_mask;
    unsigned user_id;  // GeometryInstance::set_instance_id
    ProgramRef intersection;
    ProgramRef attribute;
    const float3* vertices;  // triangles and curves
    const uint3* indices;
    const unsigned* material_indices;  // triangles, spheres and curves
    const float3* centers;             // spheres
    const float* radii;                // spheres; curves (one per vertex)
    unsigned single_radius;            // radii[0] for every sphere
    const unsigned* segments;          // curves: each segment's first vertex
    unsigned curve_type;               // curves: CurveType
    unsigned material_offset;  // materials[(material_offset + m) * ray_type_count + r]
    unsigned material_count;
    runtime::MotionRange motion;  // triangles' vertex or spheres' centre keys, or kMotionNone
    unsigned motion_points;       // points per key
};

struct GpuMaterialSlot {
    ProgramRef closest;
    ProgramRef any;
};

constexpr unsigned kGpuExceptionSlots = 32;
/// Zero-initialised: code 0 is a free slot; the first launch index is kept inverted so
/// that atomicMax finds the smallest and 0 means none.
struct GpuExceptionSlot {
    int code;
    unsigned pad;
    unsigned long long count;
    unsigned long long first_linear_inverted;
};

constexpr unsigned kGpuMaxDeviceSlots = 16;  // lucent::kMaxDevices

struct LaunchParams {
    const GpuNode* nodes;
    const unsigned* children;
    const GpuBvhNode* bvh_nodes;
    const unsigned* prim_order;
    const GpuPrimRef* prim_refs;  // beside prim_order; unused entries for Group BVHs
    const GpuBvh* bvhs;
    const GpuGeometryAccel* accels;
    const unsigned* accel_instances;
    const unsigned* accel_prim_first;
    const GpuInstance* instances;
    const GpuMaterialSlot* materials;
    const unsigned char* records;
    const ProgramRef* miss;
    const unsigned* payload_signatures;  // per ray type: sizeof(payload) << 8 | alignof(payload)
    const float* motion;  // every motion key (core::CompiledScene::motion)
    unsigned ray_type_count;
    unsigned node_count;
    unsigned max_depth;
    ProgramRef ray_generation;
    ProgramRef exception;
    uint3 launch_size;
    unsigned exception_mask;  // bit c (1..6): engine code c runs the exception program; bit 31:
                              // user codes
    unsigned long long launch_count;
    GpuExceptionSlot* exceptions;
    unsigned char* scratch;  // per-thread out-of-bounds scratch, kGpuScratchBytes each
    int3 print_index;
    unsigned print_enabled;
    unsigned device_slots;                   // devices of the Context's list (device_tea_key())
    uint4 device_keys[kGpuMaxDeviceSlots];  // per slot: generate_tea_key(initial, (slot, seed))
};

constexpr unsigned kGpuScratchBytes = 256;

/// Base address of a buffer's copy on each GPU sharing a tile queue (gather.cuh).
struct DeviceCopies {
    unsigned long long base[kGpuMaxDeviceSlots];
};

}  // namespace lucent::gpu

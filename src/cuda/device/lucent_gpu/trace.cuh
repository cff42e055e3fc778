// trace() on the GPU and the megakernel entry point (included after the generated
// dispatch): the traversal of the GPU's BVHs, which drives the trace state machine of
// src/runtime/trace_rules.h (the CPU's traversal, src/cpu/traversal.cpp, drives the same):
// Traverse the graph, running intersection and any-hit programs, then Shade with closest
// hit or miss.
#pragma once

#include "lucent/device/triangle_intersect.h"
#include "lucent_gpu/lane_refill.cuh"
#include "lucent_gpu/launch_piece.cuh"
#include "lucent_gpu/runtime.cuh"
#include "runtime/trace_rules.h"

namespace lucent::gpu {

/// The trace state machine's steps as the traversal below uses them.
__device__ __forceinline__ bool triangle_candidate(Frame& f, unsigned instance_index, unsigned prim,
                                                   float t, float2 bary) {
    return runtime::triangle_candidate(GpuPolicy{}, f, instance_index, prim, t, bary);
}

/// Slab test of a binary BVH node against the ray interval [tmin, tmax]; the far distance
/// is scaled by 1 + 2^-21 so that rounding never culls a box the ray touches, those of zero
/// thickness included (Ize 2013: the three roundings on each side need 1 + 7u, u = 2^-24).
__device__ __forceinline__ bool box_overlaps(const GpuBvhNode& n, float3 origin, float3 inv,
                                             float tmin, float tmax) {
    float3 t0 = (n.lo - origin) * inv, t1 = (n.hi - origin) * inv;
    float tn = fmaxf(fmaxf(fminf(t0.x, t1.x), fminf(t0.y, t1.y)), fmaxf(fminf(t0.z, t1.z), tmin));
    float tf = fminf(fminf(fmaxf(t0.x, t1.x), fmaxf(t0.y, t1.y)), fminf(fmaxf(t0.z, t1.z), tmax));
    return tn <= tf * (1.0f + 0x1p-21f);
}

/// The instance (position k in the accel) owning global primitive `ref`.
__device__ inline unsigned locate(const GpuGeometryAccel& ga, unsigned ref) {
    unsigned lo = 0, hi = ga.instance_count;
    while (hi - lo > 1) {
        unsigned mid = (lo + hi) / 2;
        if (params.accel_prim_first[ga.prim_first_offset + mid] <= ref)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

// Groups, Transforms and Selectors make traversal recursive; scenes whose roots are all
// GeometryGroups get none of that code.
#define LUCENT_GPU_NESTED (LUCENT_GPU_GROUPS || LUCENT_GPU_TRANSFORMS || LUCENT_GPU_SELECTORS)
#if LUCENT_GPU_NESTED
__device__ __noinline__ void traverse_node(Frame& f, unsigned node, float3 origin,
                                           float3 direction);
#endif

/// Must a trace see each triangle of this group (any-hit programs to run, instances masked,
/// culls or kRayFlagTerminateOnFirstHit), or does the closest one answer it?
__device__ __forceinline__ bool trace_needs_candidates(const Frame& f, const GpuGeometryAccel& ga) {
#if LUCENT_GPU_RAY_CONTROL
    const unsigned flags = f.ray_flags;
    if ((flags & runtime::kRayFlagsPerCandidate) || ga.instances_masked) return true;
    if (flags & kRayFlagDisableAnyHit) return false;
    const unsigned mask = flags & kRayFlagEnforceAnyHit ? ga.any_hit_enforced_mask : ga.any_hit_mask;
    return (mask >> f.ray_type) & 1u;
#else
    return (ga.any_hit_mask >> f.ray_type) & 1u;
#endif
}

__device__ __forceinline__ void geometry_group(Frame& f, const GpuGeometryAccel& ga, float3 origin,
                                               float3 direction) {
    runtime::enter_space<GpuPolicy>(f, origin, direction);
#if LUCENT_GPU_RAY_CONTROL
    f.masked_instances = ga.instances_masked;
#endif
    const float tmin = f.world_ray.tmin;
    (void)tmin;  // unused when the scene has only one kind of group
#if LUCENT_GPU_TRIANGLE_GROUPS
    if (ga.triangles_only) {
#if LUCENT_GPU_OCCLUSION
        // A facing cull or masked instances need each triangle: the exact filtered path
        // below (a leaf box mixes instances and loads no triangle).
        if (f.occlusion && !(f.ray_flags & kRayFlagsFacingCull) &&
            !(LUCENT_GPU_RAY_CONTROL && ga.instances_masked)) {
            const bool blocked =
                f.leaf_boxes
                    ? gpu_bvh_occluded_leaf_boxes(ga.triangles, origin, direction, tmin, f.closest)
                    : gpu_bvh_occluded(ga.triangles, origin, direction, tmin, f.closest);
            if (blocked) f.has_hit = f.terminated = true;
            return;
        }
        const bool closest_only = !f.occlusion && !trace_needs_candidates(f, ga);
#else
        const bool closest_only = !trace_needs_candidates(f, ga);
#endif
        GpuHit hit;
        if (closest_only) {
#if LUCENT_GPU_LANE_REFILL
            const bool found =
                gpu_bvh_closest_refilled(ga.triangles, origin, direction, tmin, f.closest, hit);
#else
            const bool found =
                gpu_bvh_closest(ga.triangles, origin, direction, tmin, f.closest, hit);
#endif
            if (found) {
                unsigned k = locate(ga, hit.prim);
                unsigned local = hit.prim - params.accel_prim_first[ga.prim_first_offset + k];
                triangle_candidate(f, params.accel_instances[ga.instance_offset + k], local, hit.t,
                                   make_float2(hit.u, hit.v));
            }
            return;
        }
        gpu_bvh_filtered(
            ga.triangles, origin, direction, tmin, f.closest, hit, [&](const GpuHit& c) -> int {
                if (!(c.t < f.closest)) return 0;
                unsigned k = locate(ga, c.prim);
                unsigned local = c.prim - params.accel_prim_first[ga.prim_first_offset + k];
                if (!triangle_candidate(f, params.accel_instances[ga.instance_offset + k], local,
                                        c.t, make_float2(c.u, c.v)))
                    return 0;
                return f.terminated ? 2 : 1;
            });
        return;
    }
#endif
#if LUCENT_GPU_GENERIC_GEOMETRY
    WatertightRay wray = make_watertight_ray(origin, direction);
    auto visit_resolved = [&](unsigned instance_index, unsigned local) {
        const GpuInstance& inst = params.instances[instance_index];
        if (inst.type == kGpuTriangles) {
            uint3 t = GpuPolicy::triangle_of(inst, local);
            float3 p0, p1, p2;
#if LUCENT_GPU_MOTION
            if (runtime::moving(inst.motion)) {
                if (!GpuPolicy{}.moving_triangle(inst, t, f.world_ray.time, p0, p1, p2))
                    return false;
            } else
#endif
            {
                p0 = inst.vertices[t.x];
                p1 = inst.vertices[t.y];
                p2 = inst.vertices[t.z];
            }
            float th, u, v;
            if (intersect_triangle_watertight(wray, p0, p1, p2, tmin, f.closest, th, u, v))
                triangle_candidate(f, instance_index, local, th, make_float2(u, v));
        }
#if LUCENT_GPU_SPHERES
        else if (inst.type == kGpuSpheres) {
            float3 center = inst.centers[local];
#if LUCENT_GPU_MOTION
            if (runtime::moving(inst.motion) &&
                !runtime::motion_center(params.motion, inst.motion, inst.motion_points, local,
                                        f.world_ray.time, center))
                return false;
#endif
            runtime::sphere_candidates(GpuPolicy{}, f, instance_index, local, origin, direction,
                                       center, inst.radii[inst.single_radius ? 0 : local]);
        }
#endif
#if LUCENT_GPU_CURVES
        else if (inst.type == kGpuCurves) {
            runtime::curve_candidates(GpuPolicy{}, f, instance_index, local, origin, direction,
                                      inst.curve_type, inst.vertices, inst.radii, inst.segments);
        }
#endif
        else {
            runtime::run_intersection(GpuPolicy{}, f, instance_index, inst, local);
        }
        return f.terminated || self().exception_code != 0;
    };
    if (ga.brute_force || ga.bvh.node_offset == ~0u) {
        if (ga.brute_force)
            for (unsigned ref = 0; ref < ga.prim_total; ++ref) {
                const unsigned k = locate(ga, ref);
                if (visit_resolved(params.accel_instances[ga.instance_offset + k],
                                   ref - params.accel_prim_first[ga.prim_first_offset + k]))
                    return;
            }
        return;
    }
    const GpuBvhNode* nodes = params.bvh_nodes + ga.bvh.node_offset;
    const GpuPrimRef* refs = params.prim_refs + ga.bvh.prim_offset;
    float3 inv = make_float3(1.0f / direction.x, 1.0f / direction.y, 1.0f / direction.z);
    unsigned stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const GpuBvhNode n = nodes[stack[--top]];
        if (!box_overlaps(n, origin, inv, tmin, f.closest)) continue;
        if (n.count > 0) {
            for (unsigned i = 0; i < n.count; ++i) {
                const GpuPrimRef r = refs[n.first + i];
                if (visit_resolved(r.instance, r.prim)) return;
            }
        } else {
            stack[top++] = n.first + 1;
            stack[top++] = n.first;
        }
    }
#endif
}

#if LUCENT_GPU_NESTED
__device__ inline void group(Frame& f, const GpuNode& n, float3 origin, float3 direction) {
    if (n.accel == ~0u) {
        for (unsigned c = 0; c < n.count; ++c) {
            traverse_node(f, params.children[n.first + c], origin, direction);
            if (f.terminated || self().exception_code) return;
        }
        return;
    }
    const GpuBvh& bvh = params.bvhs[n.accel];
    if (bvh.node_offset == ~0u) return;
    const GpuBvhNode* nodes = params.bvh_nodes + bvh.node_offset;
    const unsigned* order = params.prim_order + bvh.prim_offset;
    float3 inv = make_float3(1.0f / direction.x, 1.0f / direction.y, 1.0f / direction.z);
    unsigned stack[32];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const GpuBvhNode b = nodes[stack[--top]];
        if (!box_overlaps(b, origin, inv, f.world_ray.tmin, f.closest)) continue;
        if (b.count > 0) {
            for (unsigned i = 0; i < b.count; ++i) {
                traverse_node(f, params.children[n.first + order[b.first + i]], origin, direction);
                if (f.terminated || self().exception_code) return;
            }
        } else {
            stack[top++] = b.first + 1;
            stack[top++] = b.first;
        }
    }
}

__device__ void traverse_node(Frame& f, unsigned index, float3 origin, float3 direction) {
    const GpuNode& n = params.nodes[index];
    if (!runtime::visible(f, n.visibility_mask)) return;
    switch (n.kind) {
        case kGpuGeometryGroup:
            geometry_group(f, params.accels[n.accel], origin, direction);
            return;
        case kGpuGroup:
            group(f, n, origin, direction);
            return;
#if LUCENT_GPU_TRANSFORMS
        case kGpuTransform: {
#if LUCENT_GPU_MOTION
            if (runtime::moving(n.motion)) {
                // The keys interpolated at the ray's time; nothing below when it vanished.
                Matrix4x3 to_world, to_object;
                if (!runtime::motion_transform_at(params.motion, n.motion, f.world_ray.time,
                                                  to_world, to_object))
                    return;
                const runtime::SavedTransform saved =
                    runtime::enter_transform(f, to_world, to_object, n.instance_id);
                traverse_node(f, params.children[n.first], transform_point(to_object, origin),
                              transform_vector(to_object, direction));
                runtime::leave_transform(f, saved);
                return;
            }
#endif
            const runtime::SavedTransform saved =
                runtime::enter_transform(f, n.to_world, n.to_object, n.instance_id);
            traverse_node(f, params.children[n.first], transform_point(n.to_object, origin),
                          transform_vector(n.to_object, direction));
            runtime::leave_transform(f, saved);
            return;
        }
#endif
#if LUCENT_GPU_SELECTORS
        case kGpuSelector: {
            const unsigned child = runtime::run_visit(GpuPolicy{}, f, n.visit, origin, direction);
            if (child < n.count)
                traverse_node(f, params.children[n.first + child], origin, direction);
            return;
        }
#endif
        default:
            return;
    }
}
#endif  // LUCENT_GPU_NESTED

/// Traverses the graph below `root`. A GeometryGroup root (the common case) is traversed
/// here, inline: one call level less (ncu: returns and register restores of the call ABI
/// were a third of the stalls).
__device__ __forceinline__ void traverse_root(Frame& f, Handle root, const Ray& ray) {
    const GpuNode& root_node = params.nodes[root.index];
#if LUCENT_GPU_NESTED
    if (root_node.kind != kGpuGeometryGroup) {
        traverse_node(f, root.index, ray.origin, ray.direction);
        return;
    }
#endif
    if (runtime::visible(f, root_node.visibility_mask))
        geometry_group(f, params.accels[root_node.accel], ray.origin, ray.direction);
}

__device__ __forceinline__ void GpuPolicy::traverse(Frame& f, Handle root, const Ray& ray) const {
    traverse_root(f, root, ray);
}

/// trace(): its frame lives on this function's stack.
#if LUCENT_GPU_RAY_CONTROL
__device__ __noinline__ void trace_ray(Handle root, const Ray& ray, void* payload,
                                       unsigned payload_signature, unsigned ray_flags,
                                       unsigned ray_mask) {
    runtime::trace(GpuPolicy{}, root, ray, payload, payload_signature, ray_flags, ray_mask);
}
#else
// Without per-ray control the flags are constants (api.h refuses others at compile time).
__device__ __noinline__ void trace_ray(Handle root, const Ray& ray, void* payload,
                                       unsigned payload_signature) {
    runtime::trace(GpuPolicy{}, root, ray, payload, payload_signature, kRayFlagNone,
                   kVisibilityMaskAll);
}
#endif

#if LUCENT_GPU_OCCLUSION
/// occluded() of the device API for the roots its inline fast path leaves (see occluded()
/// below): any graph, traversed in an occlusion frame; and the checks that raise exceptions.
__device__ __noinline__ bool occluded_ray(Handle root, const Ray& ray, bool leaf_boxes,
                                          unsigned ray_flags, unsigned ray_mask) {
    const GpuPolicy p{};
    if (p.exception_pending()) return false;
    if (!runtime::occlusion_allowed(p, root, ray, leaf_boxes, ray_flags, ray_mask)) return false;
    return runtime::occluded_in_frame(p, root, ray, leaf_boxes, ray_flags, ray_mask);
}
#endif  // LUCENT_GPU_OCCLUSION

/// Records an exception in the slot of its code (slots are claimed with atomicCAS).
__device__ inline void count_exception(int code, unsigned long long linear) {
    for (unsigned i = 0; i < kGpuExceptionSlots; ++i) {
        GpuExceptionSlot& slot = params.exceptions[i];
        int seen = atomicCAS(&slot.code, 0, code);
        if (seen == 0 || seen == code) {
            atomicAdd(&slot.count, 1ull);
            atomicMax(&slot.first_linear_inverted, ~linear);  // max of ~x = min of x
            return;
        }
    }
}

}  // namespace lucent::gpu

namespace lucent {
namespace detail {
#if LUCENT_GPU_INLINE_TRACE
// The kernel's inline-trace variant, compiled only where no program that a trace runs
// traces again (src/cuda/backend/cuda_backend.cpp): the trace is inlined into the
// ray-generation program, so its frame, the ray and the payload can stay in registers and
// the call's saves and restores are gone.
__forceinline__
#endif
LUCENT_HD void trace_erased(Handle root, const Ray& ray, void* payload, const void* signature,
                           unsigned ray_flags, unsigned visibility_mask) {
    const unsigned payload_signature = unsigned(reinterpret_cast<unsigned long long>(signature));
#if !LUCENT_GPU_RAY_CONTROL
    // Without per-ray control the flags are constants (api.h refuses others at compile time).
    (void)ray_flags;
    (void)visibility_mask;
#endif
#if LUCENT_GPU_INLINE_TRACE && LUCENT_GPU_RAY_CONTROL
    runtime::trace(gpu::GpuPolicy{}, root, ray, payload, payload_signature, ray_flags,
                   visibility_mask);
#elif LUCENT_GPU_INLINE_TRACE
    runtime::trace(gpu::GpuPolicy{}, root, ray, payload, payload_signature, kRayFlagNone,
                   kVisibilityMaskAll);
#elif LUCENT_GPU_RAY_CONTROL
    gpu::trace_ray(root, ray, payload, payload_signature, ray_flags, visibility_mask);
#else
    gpu::trace_ray(root, ray, payload, payload_signature);
#endif
}
}  // namespace detail

#if LUCENT_GPU_OCCLUSION
namespace gpu {
__device__ __forceinline__ bool occluded_query(Handle root, const Ray& ray, Occlusion test,
                                               unsigned ray_flags, unsigned visibility_mask) {
    const bool leaf_boxes = test == Occlusion::kLeafBoxes;
#if LUCENT_GPU_TRIANGLE_GROUPS
    // The common shadow root, a GeometryGroup of triangles: the BVH's any-hit traversal right
    // here (occluded_ray checks the same and raises the exceptions for bad input). Flags
    // other than those occluded() implies, or a partial mask, take occluded_ray's path.
    const unsigned implied =
        kRayFlagDisableAnyHit | kRayFlagTerminateOnFirstHit | kRayFlagDisableClosestHit;
    if (root.index < gpu::params.node_count && ray.ray_type < gpu::params.ray_type_count &&
        !(ray_flags & ~implied) && visibility_mask == kVisibilityMaskAll &&
        !gpu::self().exception_code) {
        const gpu::GpuNode& node = gpu::params.nodes[root.index];
        if (node.kind == gpu::kGpuGeometryGroup &&
            (!LUCENT_GPU_RAY_CONTROL || (node.visibility_mask == kVisibilityMaskAll &&
                                         !gpu::params.accels[node.accel].instances_masked)) &&
            gpu::params.accels[node.accel].triangles_only) {
            const gpu::GpuTriangleBvhView& bvh = gpu::params.accels[node.accel].triangles;
            return leaf_boxes ? gpu::gpu_bvh_occluded_leaf_boxes(bvh, ray.origin, ray.direction,
                                                                 ray.tmin, ray.tmax)
                              : gpu::gpu_bvh_occluded(bvh, ray.origin, ray.direction, ray.tmin,
                                                      ray.tmax);
        }
    }
#endif
    return gpu::occluded_ray(root, ray, leaf_boxes, ray_flags, visibility_mask);
}
}  // namespace gpu

#if LUCENT_GPU_RAY_CONTROL
__device__ __forceinline__ bool occluded(Handle root, const Ray& ray, Occlusion test,
                                         unsigned ray_flags, unsigned visibility_mask) {
    return gpu::occluded_query(root, ray, test, ray_flags, visibility_mask);
}
#else
__device__ __forceinline__ bool occluded(Handle root, const Ray& ray, Occlusion test) {
    return gpu::occluded_query(root, ray, test, kRayFlagNone, kVisibilityMaskAll);
}
#endif
#endif

}  // namespace lucent

namespace lucent::gpu {
/// Runs the ray-generation program at launch index (x, y, z), then the exception program if
/// it raised an enabled exception.
template <class RunRayGeneration>
__device__ __forceinline__ void run_launch_index(RunRayGeneration& run_ray_generation, unsigned x,
                                                 unsigned y, unsigned z) {
    ThreadState& s = self();
    const LaunchParams& p = params;
    const unsigned long long linear =
        (unsigned long long)(z * p.launch_size.y + y) * p.launch_size.x + x;
    s.launch_index = make_uint3(x, y, z);
    s.depth = 0;
    s.exception_code = 0;
    s.frame = nullptr;
    s.context = ProgramContext::kRayGeneration;
#if LUCENT_GPU_PRINT
    s.print_here = p.print_enabled && (p.print_index.x < 0 || unsigned(p.print_index.x) == x) &&
                   (p.print_index.y < 0 || unsigned(p.print_index.y) == y) &&
                   (p.print_index.z < 0 || unsigned(p.print_index.z) == z);
#else
    s.print_here = 0;
#endif
    run_ray_generation(record(p.ray_generation));
    if (s.exception_code) {
        int code = s.exception_code;
        count_exception(code, linear);
        bool enabled = code >= kUserExceptionBase ? (p.exception_mask >> 31) & 1u
                                                  : (p.exception_mask >> code) & 1u;
        if (enabled && p.exception.id >= 0) {
            s.exception_code = 0;  // the exception program runs normally
            s.depth = 0;
            s.frame = nullptr;
            s.context = ProgramContext::kException;
            ExceptionInfo info{code, s.launch_index, s.exception_detail};
            dispatch_exception(p.exception.id, record(p.exception), info);
            if (s.exception_code) count_exception(s.exception_code, linear);
        }
    }
}

/// The megakernel's body: persistent threads take launch indices from a global counter, a
/// warp's worth at a time (Aila and Laine 2009), and run the ray-generation program on each.
/// One kernel runs one piece of the launch: linear indices [piece_first, piece_last), whole
/// rows (row = z * height + y) when the launch has more than one, counted by its own
/// `counter` (pieces may run at once, one filling the SMs another's tail leaves idle).
/// Several GPUs may share one counter (peer atomics): each then writes `device` into
/// `owners[tile]` for the tiles it takes, so each can gather the others' tiles (gather.cuh).
/// On one GPU, with LUCENT_GPU_LANE_REFILL, each lane takes its own indices instead
/// (lane_refill.cuh).
///
/// `run_ray_generation(record)` calls one ray-generation program directly: the generator
/// makes one kernel per bound ray-generation program (LUCENT_GPU_RAY_GENERATION_KERNEL
/// below, each in its own compile unit), so each kernel holds only the code its program
/// reaches, and a program that traces nothing (a denoiser's filter) gets its own small
/// register count and high occupancy instead of the tracing kernels' (docs/architecture.md,
/// "One kernel per ray-generation program").
template <class RunRayGeneration>
__device__ __forceinline__ void run_launch(RunRayGeneration run_ray_generation,
                                           unsigned long long piece_first,
                                           unsigned long long piece_last,
                                           unsigned long long* counter, unsigned char* owners,
                                           unsigned device) {
    const LaunchPiece piece(piece_first, piece_last);
    unsigned x, y, z;
#if LUCENT_GPU_LANE_REFILL
    ThreadState& s = self();
    if (!owners) {  // a tile must not be split between GPUs: refill on one GPU only
        refill_open(s);
        for (;;) {
            const unsigned long long i = refill_claim(counter);
            if (i >= piece.work) break;
            if (piece.coordinates(i, x, y, z)) run_launch_index(run_ray_generation, x, y, z);
        }
        refill_retire(s);
        return;
    }
    s.refill = 0;
#endif
    const unsigned lane = threadIdx.x & 31u;
    for (;;) {
        unsigned long long base = 0;
        if (lane == 0) {
            base = atomicAdd(counter, 32ull);
            if (owners && base < piece.work) owners[base / 32] = (unsigned char)device;
        }
        base = __shfl_sync(0xffffffffu, base, 0);
        if (base >= piece.work) return;
        if (piece.coordinates(base + lane, x, y, z)) run_launch_index(run_ray_generation, x, y, z);
    }
}
}  // namespace lucent::gpu

/// The kernel of one ray-generation program `program` (its qualified name), named `kernel`;
/// the backend launches the kernel of the entry point's program.
#define LUCENT_GPU_RAY_GENERATION_KERNEL(kernel, program)                                      \
    extern "C" __global__ void __launch_bounds__(LUCENT_GPU_BLOCK, LUCENT_GPU_MIN_BLOCKS)      \
        kernel(unsigned long long piece_first, unsigned long long piece_last,                  \
               unsigned long long* counter, unsigned char* owners, unsigned device) {          \
        ::lucent::gpu::run_launch(                                                              \
            [](const void* rec) { ::lucent::gpu::invoke(&program, rec); }, piece_first,         \
            piece_last, counter, owners, device);                                              \
    }

#include "lucent_gpu/gather.cuh"

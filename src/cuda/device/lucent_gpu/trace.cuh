// trace() on the GPU and the megakernel entry point (included after the generated
// dispatch). The same algorithm as the CPU backend (src/cpu/traversal.cpp): Traverse the
// graph, running intersection and any-hit programs, then Shade with closest hit or miss.
#pragma once

#include "lucent/device/triangle_intersect.h"
#include "lucent_gpu/runtime.cuh"

namespace lucent::gpu {

__device__ inline Matrix4x3 compose(const Matrix4x3& a, const Matrix4x3& b) {
    Matrix4x3 r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j) {
            float v =
                a.m[i * 4 + 0] * b.m[j] + a.m[i * 4 + 1] * b.m[4 + j] + a.m[i * 4 + 2] * b.m[8 + j];
            r.m[i * 4 + j] = j == 3 ? v + a.m[i * 4 + 3] : v;
        }
    return r;
}

__device__ inline uint3 triangle_of(const GpuInstance& inst, unsigned prim) {
    return inst.indices ? inst.indices[prim] : make_uint3(3 * prim, 3 * prim + 1, 3 * prim + 2);
}

__device__ inline const GpuMaterialSlot& material_slot(const GpuInstance& inst, unsigned material,
                                                       unsigned ray_type) {
    return params.materials[(inst.material_offset + material) * params.ray_type_count + ray_type];
}

__device__ inline void triangle_attributes(Frame& f, const GpuInstance& inst, unsigned prim,
                                           float2 bary, Attributes& out) {
    if (inst.attribute.id >= 0) {
        unsigned saved = f.context;
        f.context = kCtxAttribute;
        dispatch_attribute(inst.attribute.id, record(inst.attribute), prim, bary, out.bytes);
        f.context = saved;
        return;
    }
    uint3 t = triangle_of(inst, prim);
    float3 p0 = inst.vertices[t.x], p1 = inst.vertices[t.y], p2 = inst.vertices[t.z];
    TriangleAttributes* a = reinterpret_cast<TriangleAttributes*>(out.bytes);
    a->barycentrics = bary;
    a->geometric_normal = normalize(cross(p1 - p0, p2 - p0));
}

__device__ inline void commit(Frame& f, unsigned instance, unsigned prim, float t,
                              unsigned material) {
    f.has_hit = true;
    f.closest = t;
    f.hit_t = t;
    f.hit_instance = instance;
    f.hit_prim = prim;
    f.hit_material = material;
    f.hit_pending = false;
#if LUCENT_GPU_TRANSFORMS
    f.hit_transformed = f.transformed;
    if (f.transformed) {
        f.hit_to_world = f.to_world;
        f.hit_to_object = f.to_object;
    }
#endif
}

__device__ inline void copy_attributes(Attributes& dst, const Attributes& src) {
    const uint4* s = reinterpret_cast<const uint4*>(src.bytes);
    uint4* d = reinterpret_cast<uint4*>(dst.bytes);
    for (int i = 0; i < LUCENT_GPU_ATTRIBUTE_BYTES / 16; ++i) d[i] = s[i];
}

/// Runs the any-hit program on the candidate; false when it called ignore_intersection.
__device__ inline bool run_any_hit(Frame& f, ProgramRef any) {
    unsigned saved = f.context;
    f.context = kCtxAnyHit;
    f.ignore_requested = false;
    f.terminate_requested = false;
    dispatch_any_hit(any.id, record(any), f.payload, f.scratch.bytes);
    f.context = saved;
    if (f.ignore_requested) return false;
    if (f.terminate_requested) f.terminated = true;
    return true;
}

/// A triangle hit nearer than the closest so far: any-hit, then commit. True if accepted.
__device__ inline bool triangle_candidate(Frame& f, unsigned instance_index, unsigned prim, float t,
                                          float2 bary) {
#if LUCENT_GPU_OCCLUSION
    if (f.occlusion) {  // occluded(): any intersection answers the query
        f.has_hit = f.terminated = true;
        return true;
    }
#endif
    const GpuInstance& inst = params.instances[instance_index];
    unsigned material = inst.material_indices ? inst.material_indices[prim] : 0u;
    ProgramRef any = material_slot(inst, material, f.ray_type).any;
    if (any.id >= 0) {
        f.instance = instance_index;
        f.prim = prim;
        triangle_attributes(f, inst, prim, bary, f.scratch);
        f.candidate_t = t;
        if (!run_any_hit(f, any)) return false;
        commit(f, instance_index, prim, t, material);
        copy_attributes(f.hit_attr, f.scratch);
        return true;
    }
    commit(f, instance_index, prim, t, material);
    f.hit_bary = bary;
    f.hit_pending = true;
    return true;
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

__device__ __forceinline__ void geometry_group(Frame& f, const GpuGeometryAccel& ga, float3 origin,
                                               float3 direction) {
#if LUCENT_GPU_TRANSFORMS  // else the object-space ray is the world ray
    f.object_ray.origin = origin;
    f.object_ray.direction = direction;
#endif
    const float tmin = f.world_ray.tmin;
    (void)tmin;  // unused when the scene has only one kind of group
#if LUCENT_GPU_TRIANGLE_GROUPS
    if (ga.triangles_only) {
#if LUCENT_GPU_OCCLUSION
        if (f.occlusion) {
            if (gpu_bvh_occluded(ga.triangles, origin, direction, tmin, f.closest))
                f.has_hit = f.terminated = true;
            return;
        }
#endif
        GpuHit hit;
        if (!((ga.any_hit_mask >> f.ray_type) & 1u)) {
            if (gpu_bvh_closest(ga.triangles, origin, direction, tmin, f.closest, hit)) {
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
        if (inst.triangles) {
            uint3 t = triangle_of(inst, local);
            float th, u, v;
            if (intersect_triangle_watertight(wray, inst.vertices[t.x], inst.vertices[t.y],
                                              inst.vertices[t.z], tmin, f.closest, th, u, v))
                triangle_candidate(f, instance_index, local, th, make_float2(u, v));
        } else {
            f.instance = instance_index;
            f.prim = local;
            unsigned saved = f.context;
            f.context = kCtxIntersection;
            dispatch_intersection(inst.intersection.id, record(inst.intersection), local,
                                  f.scratch.bytes);
            f.context = saved;
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
    switch (n.kind) {
        case kGpuGeometryGroup:
            geometry_group(f, params.accels[n.accel], origin, direction);
            return;
        case kGpuGroup:
            group(f, n, origin, direction);
            return;
#if LUCENT_GPU_TRANSFORMS
        case kGpuTransform: {
            const bool was = f.transformed;
            const Matrix4x3 to_world = f.to_world, to_object = f.to_object;
            f.to_world = was ? compose(to_world, n.to_world) : n.to_world;
            f.to_object = was ? compose(n.to_object, to_object) : n.to_object;
            f.transformed = true;
            traverse_node(f, params.children[n.first], transform_point(n.to_object, origin),
                          transform_vector(n.to_object, direction));
            f.transformed = was;
            f.to_world = to_world;
            f.to_object = to_object;
            return;
        }
#endif
#if LUCENT_GPU_SELECTORS
        case kGpuSelector: {
#if LUCENT_GPU_TRANSFORMS
            f.object_ray.origin = origin;
            f.object_ray.direction = direction;
#endif
            unsigned saved = f.context;
            f.context = kCtxVisit;
            unsigned child = dispatch_visit(n.visit.id, record(n.visit));
            f.context = saved;
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

/// A trace frame for `ray`, before traversal.
__device__ __forceinline__ void begin_frame(Frame& f, const Ray& ray, void* payload,
                                            bool occlusion) {
    f.world_ray = ray;
#if LUCENT_GPU_TRANSFORMS
    f.object_ray = ray;
    f.transformed = false;
#endif
    f.payload = payload;
    f.ray_type = ray.ray_type;
    f.closest = ray.tmax;
    f.has_hit = false;
    f.terminated = false;
    f.occlusion = occlusion;
    f.candidate_open = false;
    f.context = kCtxIntersection;
}

/// Traverses the graph below `root`. A GeometryGroup root (the common case) is traversed
/// here, inline: one call level less (ncu: returns and register restores of the call ABI
/// were a third of the stalls).
__device__ __forceinline__ void traverse_root(Frame& f, Handle root, const Ray& ray) {
    const GpuNode& root_node = params.nodes[root.index];
#if LUCENT_GPU_NESTED
    if (root_node.kind != kGpuGeometryGroup)
        traverse_node(f, root.index, ray.origin, ray.direction);
    else
#endif
        geometry_group(f, params.accels[root_node.accel], ray.origin, ray.direction);
}

__device__ __noinline__ void trace_ray(Handle root, const Ray& ray, void* payload,
                                       unsigned payload_signature) {
    ThreadState& s = self();
    if (s.exception_code) return;  // an exception ends the launch index's work
    if (ray.ray_type >= params.ray_type_count) {
        detail::raise_exception(kExceptionInvalidRayType, ray.ray_type);
        return;
    }
    if (payload_signature != params.payload_signatures[ray.ray_type]) {
        detail::raise_exception(kExceptionPayloadTypeMismatch, ray.ray_type);
        return;
    }
    if (root.index >= params.node_count) {
        detail::raise_exception(kExceptionInvalidHandle, root.index);
        return;
    }
    if (s.depth >= LUCENT_GPU_MAX_DEPTH) {
        detail::raise_exception(kExceptionStackOverflow, s.depth + 1);
        return;
    }
    Frame f;
    begin_frame(f, ray, payload, /*occlusion=*/false);
    Frame* outer = s.frame;
    s.frame = &f;
    ++s.depth;
    traverse_root(f, root, ray);
    if (!s.exception_code) {
        if (f.has_hit) {
            const GpuInstance& inst = params.instances[f.hit_instance];
            if (f.hit_pending) {
                // The attribute program runs as at the hit: its primitive, transform and ray.
                f.instance = f.hit_instance;
                f.prim = f.hit_prim;
#if LUCENT_GPU_TRANSFORMS
                f.object_ray = ray;
                f.transformed = f.hit_transformed;
                if (f.hit_transformed) {
                    f.to_world = f.hit_to_world;
                    f.to_object = f.hit_to_object;
                    f.object_ray.origin = transform_point(f.hit_to_object, ray.origin);
                    f.object_ray.direction = transform_vector(f.hit_to_object, ray.direction);
                }
#endif
                triangle_attributes(f, inst, f.hit_prim, f.hit_bary, f.hit_attr);
            }
#if LUCENT_GPU_TRANSFORMS
            f.object_ray = ray;
#endif
            ProgramRef closest = material_slot(inst, f.hit_material, f.ray_type).closest;
            if (closest.id >= 0) {
                f.context = kCtxClosestHit;
                dispatch_closest_hit(closest.id, record(closest), payload, f.hit_attr.bytes);
            }
        } else {
            ProgramRef miss = params.miss[f.ray_type];
            if (miss.id >= 0) {
                f.context = kCtxMiss;
                dispatch_miss(miss.id, record(miss), payload);
            }
        }
    }
    --s.depth;
    s.frame = outer;
}

#if LUCENT_GPU_OCCLUSION
/// occluded() of the device API for the roots its inline fast path leaves (see occluded()
/// below): any graph, traversed in an occlusion frame; and the checks that raise exceptions.
__device__ __noinline__ bool occluded_ray(Handle root, const Ray& ray) {
    ThreadState& s = self();
    if (s.exception_code) return false;
    if (ray.ray_type >= params.ray_type_count) {
        detail::raise_exception(kExceptionInvalidRayType, ray.ray_type);
        return false;
    }
    if (root.index >= params.node_count) {
        detail::raise_exception(kExceptionInvalidHandle, root.index);
        return false;
    }
    if (s.depth >= LUCENT_GPU_MAX_DEPTH) {
        detail::raise_exception(kExceptionStackOverflow, s.depth + 1);
        return false;
    }
    Frame f;
    begin_frame(f, ray, nullptr, /*occlusion=*/true);
    Frame* outer = s.frame;
    s.frame = &f;
    ++s.depth;
    traverse_root(f, root, ray);
    --s.depth;
    s.frame = outer;
    return f.has_hit && !s.exception_code;
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
LUCENT_HD void trace_erased(Handle root, const Ray& ray, void* payload, const void* signature) {
    gpu::trace_ray(root, ray, payload, unsigned(reinterpret_cast<unsigned long long>(signature)));
}
}  // namespace detail

#if LUCENT_GPU_OCCLUSION
__device__ __forceinline__ bool occluded(Handle root, const Ray& ray) {
#if LUCENT_GPU_TRIANGLE_GROUPS
    // The common shadow root, a GeometryGroup of triangles: the BVH's any-hit traversal right
    // here (occluded_ray checks the same and raises the exceptions for bad input).
    if (root.index < gpu::params.node_count && ray.ray_type < gpu::params.ray_type_count &&
        !gpu::self().exception_code) {
        const gpu::GpuNode& node = gpu::params.nodes[root.index];
        if (node.kind == gpu::kGpuGeometryGroup && gpu::params.accels[node.accel].triangles_only)
            return gpu::gpu_bvh_occluded(gpu::params.accels[node.accel].triangles, ray.origin,
                                         ray.direction, ray.tmin, ray.tmax);
    }
#endif
    return gpu::occluded_ray(root, ray);
}
#endif

LUCENT_HD bool report_intersection(unsigned material) {
    gpu::Frame& f = *gpu::self().frame;
    if (f.context != gpu::kCtxIntersection || !f.candidate_open) return false;
    f.candidate_open = false;
    const gpu::GpuInstance& inst = gpu::params.instances[f.instance];
    if (material >= inst.material_count) {
        detail::raise_exception(kExceptionMaterialIndexOutOfRange, material);
        return false;
    }
#if LUCENT_GPU_OCCLUSION
    if (f.occlusion) {  // occluded(): no any-hit, the first intersection ends traversal
        f.has_hit = f.terminated = true;
        return true;
    }
#endif
    gpu::ProgramRef any = gpu::material_slot(inst, material, f.ray_type).any;
    if (any.id >= 0 && !gpu::run_any_hit(f, any)) return false;
    gpu::commit(f, f.instance, f.prim, f.candidate_t, material);
    gpu::copy_attributes(f.hit_attr, f.scratch);
    return true;
}
}  // namespace lucent

/// The megakernel: persistent threads take launch indices from a global counter, a warp's
/// worth at a time (Aila and Laine 2009), and run the ray-generation program on each. One
/// kernel runs one piece of the launch: linear indices [piece_first, piece_last), whole rows
/// (row = z * height + y) when the launch has more than one, counted by its own `counter`
/// (pieces may run at once, one filling the SMs another's tail leaves idle). Several GPUs
/// may share one counter (peer atomics): each then writes `device` into `owners[tile]` for
/// the tiles it takes, so each can gather the others' tiles (gather.cuh).
extern "C" __global__ void __launch_bounds__(LUCENT_GPU_BLOCK, LUCENT_GPU_MIN_BLOCKS)
    lucent_megakernel(unsigned long long piece_first, unsigned long long piece_last,
                      unsigned long long* counter, unsigned char* owners, unsigned device) {
    using namespace lucent;
    using namespace lucent::gpu;
    ThreadState& s = self();
    const LaunchParams& p = params;
    const unsigned lane = threadIdx.x & 31u;
#if LUCENT_GPU_TILES
    // Launches of several rows: a warp takes an 8x4 tile of launch indices, so neighbouring
    // rays, and their secondary rays, run together (less divergence than a row of 32).
    const bool tiled = p.launch_size.y > 1 || p.launch_size.z > 1;
#else
    const bool tiled = false;
#endif
    const unsigned long long first_row = piece_first / p.launch_size.x;
    const unsigned long long end_row = piece_last / p.launch_size.x;
    const unsigned tiles_x = (p.launch_size.x + 7) / 8;
    const unsigned long long work =
        tiled ? 32ull * tiles_x * ((end_row - first_row + 3) / 4) : piece_last - piece_first;
    for (;;) {
        unsigned long long base = 0;
        if (lane == 0) {
            base = atomicAdd(counter, 32ull);
            if (owners && base < work) owners[base / 32] = (unsigned char)device;
        }
        base = __shfl_sync(0xffffffffu, base, 0);
        if (base >= work) return;
        unsigned x, y, z;
        if (tiled) {
            const unsigned long long tile = base / 32;
            x = unsigned(tile % tiles_x) * 8 + (lane & 7u);
            const unsigned long long row = first_row + (tile / tiles_x) * 4 + (lane >> 3);
            if (x >= p.launch_size.x || row >= end_row) continue;
            y = unsigned(row % p.launch_size.y);
            z = unsigned(row / p.launch_size.y);
        } else {
            unsigned long long index = piece_first + base + lane;
            if (index >= piece_last) continue;
            x = unsigned(index % p.launch_size.x);
            unsigned long long rest = index / p.launch_size.x;
            y = unsigned(rest % p.launch_size.y);
            z = unsigned(rest / p.launch_size.y);
        }
        const unsigned long long linear =
            (unsigned long long)(z * p.launch_size.y + y) * p.launch_size.x + x;
        s.launch_index = make_uint3(x, y, z);
        s.depth = 0;
        s.exception_code = 0;
        s.frame = nullptr;
        s.context = kCtxRayGeneration;
#if LUCENT_GPU_PRINT
        s.print_here = p.print_enabled && (p.print_index.x < 0 || unsigned(p.print_index.x) == x) &&
                       (p.print_index.y < 0 || unsigned(p.print_index.y) == y) &&
                       (p.print_index.z < 0 || unsigned(p.print_index.z) == z);
#else
        s.print_here = 0;
#endif
        dispatch_ray_generation(p.ray_generation.id, record(p.ray_generation));
        if (s.exception_code) {
            int code = s.exception_code;
            count_exception(code, linear);
            bool enabled = code >= kUserExceptionBase ? (p.exception_mask >> 31) & 1u
                                                      : (p.exception_mask >> code) & 1u;
            if (enabled && p.exception.id >= 0) {
                s.exception_code = 0;  // the exception program runs normally
                s.depth = 0;
                s.frame = nullptr;
                s.context = kCtxException;
                ExceptionInfo info{code, s.launch_index, s.exception_detail};
                dispatch_exception(p.exception.id, record(p.exception), info);
                if (s.exception_code) count_exception(s.exception_code, linear);
            }
        }
    }
}

#include "lucent_gpu/gather.cuh"

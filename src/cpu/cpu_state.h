// Per-thread state of the CPU backend and the policy that instantiates the trace state
// machine (src/runtime/trace_rules.h) for it: the scene is a core::CompiledScene, programs
// are called through their thunks, an exception is a C++ exception that unwinds the launch
// index, and the traversal is the Traverser of traversal.cpp.
#pragma once

#include <cstdint>
#include <cstring>

#include "core/compiled_scene.h"
#include "core/program_exception.h"
#include "runtime/trace_rules.h"

namespace lucent::cpu {

using core::ProgramException;
using runtime::ProgramContext;

struct ThreadState;
class DeferredQueue;

struct CpuPolicy {
    using Thread = ThreadState;
    using Instance = core::CompiledInstance;
    using Program = const core::CompiledProgram*;
    using PayloadTag = const void*;  // the payload type's detail::TypeTag
    static constexpr bool kTransforms = true;
    static constexpr bool kOcclusion = true;
    static constexpr bool kRayControl = true;
    static constexpr unsigned kAttributeBytes = kMaxAttributeBytes;

    ThreadState* ts;

    ThreadState& thread() const { return *ts; }
    [[noreturn]] void raise(int code, unsigned detail) const {
        throw ProgramException{code, detail};
    }
    bool exception_pending() const { return false; }  // a raised exception has unwound

    inline const core::CompiledScene& scene() const;
    unsigned ray_type_count() const { return unsigned(scene().ray_types.size()); }
    bool payload_matches(unsigned ray_type, const void* tag) const {
        return detail::same_type_tag(tag, scene().ray_types[ray_type].payload->tag);
    }
    unsigned node_count() const { return unsigned(scene().nodes.size()); }
    unsigned max_depth() const { return scene().max_depth; }
    const Ray& no_ray() const {
        static const Ray none{};
        return none;
    }

    const Instance& instance(unsigned index) const { return scene().instances[index]; }
    unsigned material_count(const Instance& inst) const { return unsigned(inst.materials.size()); }
    unsigned primitive_material(const Instance& inst, unsigned prim) const {
        return inst.material_indices ? inst.material_indices[prim] : 0u;
    }
    void triangle(const Instance& inst, unsigned prim, float3& p0, float3& p1, float3& p2) const {
        const uint3 t = inst.triangle(prim);
        if (runtime::moving(inst.motion)) {  // at the time of the trace being shaded
            moving_triangle(inst, t, frame_time(), p0, p1, p2);
            return;
        }
        p0 = inst.vertices[t.x];
        p1 = inst.vertices[t.y];
        p2 = inst.vertices[t.z];
    }
    Program any_hit(const Instance& inst, unsigned material, unsigned ray_type) const {
        return &inst.materials[material].any_hit[ray_type];
    }
    Program closest_hit(const Instance& inst, unsigned material, unsigned ray_type) const {
        return &inst.materials[material].closest_hit[ray_type];
    }
    Program miss(unsigned ray_type) const { return &scene().miss[ray_type]; }
    Program attribute(const Instance& inst) const { return &inst.attribute; }
    bool opaque(const Instance& inst) const { return inst.opaque; }
    unsigned visibility_mask(const Instance& inst) const { return inst.visibility_mask; }
    unsigned user_id(const Instance& inst) const { return inst.user_id; }
    bool bound(Program program) const { return bool(*program); }

    void call_any_hit(Program any, void* payload, const void* attr) const {
        any->entry<HitFn>()(any->rec(), payload, attr);
    }
    void call_closest_hit(Program closest, void* payload, const void* attr) const {
        closest->entry<HitFn>()(closest->rec(), payload, attr);
    }
    void call_miss(Program miss, void* payload) const {
        miss->entry<MissFn>()(miss->rec(), payload);
    }
    void call_attribute(Program attribute, unsigned prim, float2 bary, void* out) const {
        attribute->entry<AttributeFn>()(attribute->rec(), prim, bary, out);
    }
    void call_intersection(const Instance& inst, unsigned prim, void* attr) const {
        inst.intersection.entry<IntersectionFn>()(inst.intersection.rec(), prim, attr);
    }
    unsigned call_visit(Program visit) const { return visit->entry<VisitFn>()(visit->rec()); }
    template <class Attributes>
    void copy_attributes(Attributes& dst, const Attributes& src, const Instance& inst) const {
        std::memcpy(dst.bytes, src.bytes, inst.attributes->size);
    }
    /// The Traverser over the compiled graph (traversal.cpp).
    /// Traverses the graph below `root` with the frame's ray (`ray` is what begin_frame
    /// copied into it). Inline and not reading `ray`, so a trace's ray never has its address
    /// taken: it stays in registers up to the frame (no store-forwarding stall).
    void traverse(runtime::TraceFrame<CpuPolicy>& frame, Handle root, const Ray&) const {
        traverse_frame(frame, root);
    }
    void traverse_frame(runtime::TraceFrame<CpuPolicy>& frame, Handle root) const;

    inline float frame_time() const;  // the innermost trace's ray time
    /// A moving triangle's vertices at `time`; false when it is absent then.
    bool moving_triangle(const Instance& inst, uint3 t, float time, float3& p0, float3& p1,
                         float3& p2) const {
        unsigned key;
        float frac;
        const bool present = runtime::motion_key(inst.motion, time, key, frac);
        const float* motion = scene().motion.data();
        p0 = runtime::motion_point(motion, inst.motion, inst.motion_points, t.x, key, frac);
        p1 = runtime::motion_point(motion, inst.motion, inst.motion_points, t.y, key, frac);
        p2 = runtime::motion_point(motion, inst.motion, inst.motion_points, t.z, key, frac);
        return present;
    }
};

using TraceFrame = runtime::TraceFrame<CpuPolicy>;
using AttributeStorage = TraceFrame::Attributes;

struct ThreadState {
    const core::CompiledScene* scene = nullptr;
    uint3 launch_index{0, 0, 0};  // written by set_launch_index()
    uint3 launch_size{1, 1, 1};
    const uint4* device_keys = nullptr;  // per device slot (device_tea_key())
    unsigned device_slots = 1;
    unsigned depth = 0;           // active traces
    TraceFrame* frame = nullptr;  // the innermost, on the stack of its trace
    ProgramContext context = ProgramContext::kRayGeneration;  // outside any trace
    bool print_here = false;
    // The worker's queue of the rays its ray-generation programs defer (deferred_rays.h);
    // null outside a launch's worker.
    DeferredQueue* deferred = nullptr;
    // The worker's frame below which its programs' frames lie: a deferred ray's payload
    // between it and the deferring call is a program's local (require_outside_programs).
    const char* programs_stack_top = nullptr;
};

/// Sets ts.launch_index as launch_index() reads it: (x, y) in one 8-byte store, z in one
/// 4-byte store. The x86-64 ABI returns a uint3 as (x, y) in one register and z in another,
/// so the ray-generation program's first call loads it that way; a store the compiler
/// happened to split otherwise (x alone, then y and z together) cannot be forwarded to that
/// load, and the stall cost a third of a one-ray-per-index launch (perf, 2026-12).
inline void set_launch_index(ThreadState& ts, uint3 index) {
    const uint64_t xy = uint64_t(index.x) | uint64_t(index.y) << 32;
    std::memcpy(&ts.launch_index.x, &xy, sizeof xy);
    ts.launch_index.z = index.z;
}

inline const core::CompiledScene& CpuPolicy::scene() const {
    return *ts->scene;
}
inline float CpuPolicy::frame_time() const {
    return ts->frame->world_ray.time;
}

/// The calling thread's state (set by the launch loop).
ThreadState& thread_state();
void set_thread_state(ThreadState* state);
/// Throws the error a program gets for passing ray flags or a mask from a module that does
/// not declare kUsesRayFlags (the GPU's megakernel would not compile the call).
void require_ray_flags_declared();

/// Throws lucent::Error when `object` (what `call` writes after the calling program has
/// returned) lies in the frame of a program on this thread's stack: it would be gone.
void require_outside_programs(const ThreadState& ts, const void* object, const char* call,
                              const char* what);

/// Throws the error a program gets for calling occluded() from a scene whose modules do
/// not declare kUsesOccluded (the GPU's megakernel would not compile the call).
void require_occluded_declared(const core::CompiledScene& scene);

/// occluded() of the device API.
bool occluded(ThreadState& ts, Handle root, const Ray& ray, Occlusion test, unsigned ray_flags,
              unsigned ray_mask);

}  // namespace lucent::cpu

namespace lucent::runtime {
/// The policy of the calling thread (device_api.h).
inline cpu::CpuPolicy backend() {
    return cpu::CpuPolicy{&cpu::thread_state()};
}
}  // namespace lucent::runtime

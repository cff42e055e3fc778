// The device API (lucent/device/api.h) as the CPU backend implements it: every call reads
// or writes the calling thread's ThreadState. The functions that read or change a trace
// follow the shared trace state machine (runtime/device_api.h).
#include <cstdio>
#include <mutex>
#include <string>

#include "cpu/cpu_state.h"
#include "cpu/deferred_rays.h"
#include "lucent/device/api.h"
#include "lucent/error.h"

namespace lucent {

namespace cpu {
namespace {
thread_local ThreadState* t_state = nullptr;
std::mutex g_print_mutex;
}  // namespace

ThreadState& thread_state() {
    // Bounding-box programs run on the host thread during the acceleration build, outside
    // any launch: they see an idle state (no trace, launch index 0, printing off).
    static thread_local ThreadState idle{.context = ProgramContext::kBoundingBox};
    return t_state ? *t_state : idle;
}
void set_thread_state(ThreadState* state) {
    t_state = state;
}
void require_ray_flags_declared() {
    // The GPU's megakernel would not compile such a call either (lucent/device/api.h).
    if (!thread_state().scene || !thread_state().scene->uses_ray_flags)
        throw Error(
            "trace() or occluded() is given ray flags or a visibility mask, but no module of "
            "this scene declares it; declare it in the module that calls it: "
            "LUCENT_MODULE(name, lucent::kUsesRayFlags)");
}

void require_outside_programs(const ThreadState& ts, const void* object, const char* call,
                              const char* what) {
    // Frames grow down: the programs' lie between this call's and the worker's.
    const char* here = static_cast<const char*>(__builtin_frame_address(0));
    const char* at = static_cast<const char*>(object);
    if (ts.programs_stack_top && at >= here && at < ts.programs_stack_top)
        throw Error(std::string(call) + " is given a " + what +
                    " that is a local variable of the calling program; the ray is traced "
                    "after the program returns, when the variable is gone. Pass an element "
                    "of a buffer instead (for example rec.hits[launch_index().x])");
}

/// May a deferred ray wait in the queue? Only a ray-generation program's, outside any trace:
/// elsewhere (hit programs, the exception program) it is traced at once.
static bool may_defer(const ThreadState& ts) {
    return ts.deferred && ts.depth == 0 && ts.context == ProgramContext::kRayGeneration;
}

/// A deferred ray's fields written into its queue entry from the call's arguments. A copy
/// of the Ray the call built on the stack would load its 4-byte stores with 16-byte loads:
/// a store-forwarding stall that was 44 % of occluded_deferred_fields()' time (perf).
[[gnu::always_inline]] static inline void store_ray(Ray& out, float3 origin, float3 direction,
                                                    float tmin, float tmax, unsigned ray_type,
                                                    float time) {
    out.origin = origin;
    out.tmin = tmin;
    out.direction = direction;
    out.tmax = tmax;
    out.ray_type = ray_type;
    out.time = time;
}
}  // namespace cpu

namespace detail {
// Flattened: with runtime::trace inlined the ray stays in registers up to the traversal
// (called out of line, it re-read the ray just stored here with wider loads: the same
// store-forwarding stall as across the program's call).
[[gnu::flatten]] void trace_fields(Handle root, float3 origin, float3 direction, float tmin,
                                   float tmax, unsigned ray_type, float time, void* payload,
                                   const void* payload_tag, unsigned ray_flags,
                                   unsigned visibility_mask) {
    const Ray ray{origin, tmin, direction, tmax, ray_type, time};
    if ((ray_flags | (visibility_mask ^ kVisibilityMaskAll)) != 0)
        cpu::require_ray_flags_declared();
    runtime::trace(runtime::backend(), root, ray, payload, payload_tag, ray_flags, visibility_mask);
}

bool occluded_fields(Handle root, float3 origin, float3 direction, float tmin, float tmax,
                     unsigned ray_type, float time, unsigned occlusion, unsigned ray_flags,
                     unsigned visibility_mask) {
    const Ray ray{origin, tmin, direction, tmax, ray_type, time};
    if ((ray_flags | (visibility_mask ^ kVisibilityMaskAll)) != 0)
        cpu::require_ray_flags_declared();
    return cpu::occluded(cpu::thread_state(), root, ray, Occlusion(occlusion), ray_flags,
                         visibility_mask);
}

void trace_deferred_fields(Handle root, float3 origin, float3 direction, float tmin, float tmax,
                           unsigned ray_type, float time, void* payload, const void* payload_tag) {
    const Ray ray{origin, tmin, direction, tmax, ray_type, time};
    cpu::ThreadState& ts = cpu::thread_state();
    if (!cpu::may_defer(ts)) {
        runtime::trace(runtime::backend(), root, ray, payload, payload_tag, kRayFlagNone,
                       kVisibilityMaskAll);
        return;
    }
    cpu::require_outside_programs(ts, payload, "trace_deferred()", "payload");
    // trace()'s checks now, so that an exception is the deferring program's, as trace()'s.
    runtime::trace_allowed(cpu::CpuPolicy{&ts}, root, ray, payload_tag, kRayFlagNone,
                           kVisibilityMaskAll);
    cpu::DeferredTrace& q = ts.deferred->add_trace();
    cpu::store_ray(q.ray, origin, direction, tmin, tmax, ray_type, time);
    q.root = root;
    q.payload = payload;
    q.index = ts.launch_index;
}

void occluded_deferred_fields(Handle root, float3 origin, float3 direction, float tmin, float tmax,
                              unsigned ray_type, float time, unsigned occlusion, void* flag,
                              void (*write_flag)(void*, bool)) {
    const Ray ray{origin, tmin, direction, tmax, ray_type, time};
    cpu::ThreadState& ts = cpu::thread_state();
    if (!cpu::may_defer(ts)) {
        write_flag(flag, cpu::occluded(ts, root, ray, Occlusion(occlusion), kRayFlagNone,
                                       kVisibilityMaskAll));
        return;
    }
    cpu::require_occluded_declared(*ts.scene);
    cpu::require_outside_programs(ts, flag, "occluded_deferred()", "flag");
    runtime::occlusion_allowed(cpu::CpuPolicy{&ts}, root, ray,
                               Occlusion(occlusion) == Occlusion::kLeafBoxes, kRayFlagNone,
                               kVisibilityMaskAll);
    cpu::DeferredOcclusion& q = ts.deferred->add_occlusion();
    cpu::store_ray(q.ray, origin, direction, tmin, tmax, ray_type, time);
    q.root = root;
    q.test = Occlusion(occlusion);
    q.flag = flag;
    q.write_flag = write_flag;
    q.index = ts.launch_index;
}

void raise_exception(int code, unsigned detail) {
    throw cpu::ProgramException{code, detail};
}

bool print_enabled_here() {
    return cpu::thread_state().print_here;
}

void print_text(const char* text) {
    std::lock_guard lock(cpu::g_print_mutex);
    std::fputs(text, stdout);
    std::fflush(stdout);
}
}  // namespace detail

uint3 launch_index() {
    return cpu::thread_state().launch_index;
}
uint3 launch_size() {
    return cpu::thread_state().launch_size;
}
uint4 device_tea_key() {
    const cpu::ThreadState& ts = cpu::thread_state();
    return ts.device_keys[device_slot_of(ts.launch_index, ts.launch_size, ts.device_slots)];
}

}  // namespace lucent

#include "runtime/device_api.h"

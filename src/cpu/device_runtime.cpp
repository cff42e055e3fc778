// The device API (lucent/device/api.h) as the CPU backend implements it: every call
// reads or writes the calling thread's ThreadState.
#include <cstdio>
#include <mutex>

#include "cpu/cpu_state.h"
#include "lucent/device/api.h"

namespace lucent {

namespace cpu {
namespace {
thread_local ThreadState* t_state = nullptr;
std::mutex g_print_mutex;
const Ray kNoRay{};
}  // namespace

ThreadState& thread_state() {
    // Bounding-box programs run on the host thread during the acceleration build, outside
    // any launch: they see an idle state (no trace, launch index 0, printing off).
    static thread_local ThreadState idle;
    return t_state ? *t_state : idle;
}
void set_thread_state(ThreadState* state) {
    t_state = state;
}
bool report_candidate(ThreadState& ts, unsigned material);
}  // namespace cpu

using cpu::ProgramContext;
using cpu::TraceFrame;

namespace detail {
bool current_transform(const Matrix4x3*& to_world, const Matrix4x3*& to_object) {
    TraceFrame* f = cpu::thread_state().current();
    if (!f) return false;
    if (f->context == ProgramContext::kClosestHit) {
        if (!f->hit.transformed) return false;
        to_world = &f->hit.to_world;
        to_object = &f->hit.to_object;
        return true;
    }
    if (f->context == ProgramContext::kMiss || !f->transformed) return false;
    to_world = &f->to_world;
    to_object = &f->to_object;
    return true;
}

void trace_erased(Handle root, const Ray& ray, void* payload, const void* payload_tag) {
    cpu::trace(cpu::thread_state(), root, ray, payload, payload_tag);
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

const Ray& current_ray() {
    TraceFrame* f = cpu::thread_state().current();
    if (!f) return cpu::kNoRay;
    switch (f->context) {
        case ProgramContext::kIntersection:
        case ProgramContext::kAnyHit:
        case ProgramContext::kVisit:
        case ProgramContext::kAttribute:
            return f->object_ray;
        default:
            return f->world_ray;
    }
}

float t_hit() {
    TraceFrame* f = cpu::thread_state().current();
    if (!f) return 0.0f;
    switch (f->context) {
        case ProgramContext::kAnyHit:
            return f->candidate_t;
        case ProgramContext::kClosestHit:
            return f->hit.t;
        case ProgramContext::kMiss:
            return f->world_ray.tmax;
        default:
            return f->closest;
    }
}

unsigned primitive_index() {
    TraceFrame* f = cpu::thread_state().current();
    if (!f) return 0;
    return f->context == ProgramContext::kClosestHit ? f->hit.prim : f->prim;
}

bool occluded(Handle root, const Ray& ray) {
    return cpu::occluded(cpu::thread_state(), root, ray);
}

bool potential_intersection(float t) {
    TraceFrame* f = cpu::thread_state().current();
    if (!f || f->context != ProgramContext::kIntersection) return false;
    f->candidate_open = t > f->world_ray.tmin && t < f->closest;
    if (f->candidate_open) f->candidate_t = t;
    return f->candidate_open;
}

bool report_intersection(unsigned material_index) {
    return cpu::report_candidate(cpu::thread_state(), material_index);
}

void ignore_intersection() {
    TraceFrame* f = cpu::thread_state().current();
    if (f && f->context == ProgramContext::kAnyHit) f->ignore_requested = true;
}

void terminate_ray() {
    TraceFrame* f = cpu::thread_state().current();
    if (f && f->context == ProgramContext::kAnyHit) f->terminate_requested = true;
}

}  // namespace lucent

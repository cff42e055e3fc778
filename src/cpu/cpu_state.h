// Per-thread state of the CPU backend: the launch index, and a frame per active trace
// (the ray, its payload, the closest hit so far and the traversal position), which the
// device API functions read and write.
#pragma once

#include <vector>

#include "core/compiled_scene.h"
#include "core/program_exception.h"

namespace lucent::cpu {

constexpr size_t kAttributeBytes = 256;

using core::ProgramException;

enum class ProgramContext {
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

struct alignas(16) AttributeStorage {
    unsigned char bytes[kAttributeBytes];
};

/// The committed (closest so far) hit of a trace.
struct HitState {
    float t = 0;
    unsigned instance = 0;  // CompiledScene::instances index
    unsigned prim = 0;
    unsigned material = 0;
    float2 barycentrics{0, 0};
    bool attributes_pending = false;  // triangles: attributes computed at closest-hit time
    bool transformed = false;
    Matrix4x3 to_world{}, to_object{};
    AttributeStorage attributes;
};

struct TraceFrame {
    Ray world_ray;   // as passed to trace()
    Ray object_ray;  // in the space of the node being traversed
    void* payload = nullptr;
    unsigned ray_type = 0;
    float closest = 0;  // upper end of the ray interval: shrinks with each committed hit
    bool has_hit = false;
    bool terminated = false;
    bool occlusion = false;  // occluded(): the first intersection ends it, no programs run
    HitState hit;
    // Traversal position, for intersection and any-hit programs.
    const core::CompiledInstance* instance = nullptr;
    unsigned instance_index = 0;
    unsigned prim = 0;
    bool transformed = false;
    Matrix4x3 to_world{}, to_object{};
    // Candidate hit of the intersection program being run.
    float candidate_t = 0;
    bool candidate_open = false;
    AttributeStorage scratch;
    // Any-hit outcome.
    bool ignore_requested = false;
    bool terminate_requested = false;
    ProgramContext context = ProgramContext::kRayGeneration;
};

struct ThreadState {
    const core::CompiledScene* scene = nullptr;
    uint3 launch_index{0, 0, 0};
    uint3 launch_size{1, 1, 1};
    const uint4* device_keys = nullptr;  // per device slot (device_tea_key())
    unsigned device_slots = 1;
    unsigned depth = 0;              // active traces
    std::vector<TraceFrame> frames;  // frames[depth - 1] is the innermost trace
    ProgramContext context = ProgramContext::kRayGeneration;  // outside any trace
    bool print_here = false;
    TraceFrame* current() { return depth ? &frames[depth - 1] : nullptr; }
};

/// The calling thread's state (set by the launch loop).
ThreadState& thread_state();
void set_thread_state(ThreadState* state);

/// Runs one trace (the device API's trace()).
void trace(ThreadState& ts, Handle root, const Ray& ray, void* payload, const void* payload_tag);
/// occluded() of the device API.
bool occluded(ThreadState& ts, Handle root, const Ray& ray);

}  // namespace lucent::cpu

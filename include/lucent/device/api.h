// The device API: what a program may call. The rules of the functions that read or change
// a trace are written once, in src/runtime/ (device_api.h there defines them for both
// backends); each backend implements the others (the CPU's in src/cpu/device_runtime.cpp,
// the GPU's in src/cuda/device/lucent_gpu/runtime.cuh).
#pragma once

#include "lucent/device/device_slot.h"
#include "lucent/device/module.h"
#include "lucent/device/types.h"

#if !LUCENT_GPU_CODE
#include <cstddef>
#include <cstdio>
#include <string_view>
#include <type_traits>
#endif

namespace lucent {
namespace detail {
#if !LUCENT_GPU_CODE
/// A C++ type's readable name (GCC's and Clang's __PRETTY_FUNCTION__ spelling).
template <class T>
constexpr std::string_view type_name_of() {
    std::string_view p = __PRETTY_FUNCTION__;  // "... [with T = Name; ...]" or "[T = Name]"
    size_t begin = p.find("T = ") + 4;
    size_t end = p.find_first_of(";]", begin);
    return p.substr(begin, end - begin);
}
/// sizeof and alignof, 0 for a function type (a callable program's signature).
template <class T>
constexpr size_t size_of_type() {
    if constexpr (std::is_function_v<T>) return 0;
    else return sizeof(T);
}
template <class T>
constexpr size_t align_of_type() {
    if constexpr (std::is_function_v<T>) return 0;
    else return alignof(T);
}
/// What the host knows of a type without RTTI: its name, size and alignment.
struct TypeIdentity {
    std::string_view name;
    size_t size;
    size_t align;
    constexpr bool operator==(const TypeIdentity&) const = default;
};
/// One object per C++ type, whose address identifies payload types in trace(). A module
/// compiled at run time into a shared library (Context::add_module) has its own copy of
/// each tag, so two tags are the same type when their addresses or their identities are.
template <class T>
struct TypeTag {
    static constexpr TypeIdentity id{type_name_of<T>(), size_of_type<T>(), align_of_type<T>()};
};
/// Are the TypeTag ids `a` and `b` the same type (in this binary or across binaries)?
/// (Types in an anonymous namespace are only ever the same in one binary.)
inline bool same_type_tag(const void* a, const void* b) {
    if (a == b) return true;
    if (!a || !b) return false;
    const TypeIdentity& x = *static_cast<const TypeIdentity*>(a);
    return x == *static_cast<const TypeIdentity*>(b) &&
           x.name.find("(anonymous namespace)") == std::string_view::npos;
}
#endif
LUCENT_HD void trace_erased(Handle root, const Ray& ray, void* payload, const void* payload_tag,
                           unsigned ray_flags, unsigned visibility_mask);
#if !LUCENT_GPU_CODE
// The CPU backend's trace() and occluded() take the ray's fields by value, in registers. A
// Ray the caller has just built on its stack and the callee copies with wider loads than
// the caller's stores cannot be forwarded from the store buffer: that stall cost about a
// tenth of a primary ray's time on Sponza (perf, 2026-12).
void trace_fields(Handle root, float3 origin, float3 direction, float tmin, float tmax,
                  unsigned ray_type, float time, void* payload, const void* payload_tag, unsigned ray_flags,
                  unsigned visibility_mask);
bool occluded_fields(Handle root, float3 origin, float3 direction, float tmin, float tmax,
                     unsigned ray_type, float time, unsigned occlusion, unsigned ray_flags,
                     unsigned visibility_mask);
#endif
#if LUCENT_GPU_CODE
// On the GPU an exception cannot unwind: it is recorded, every later trace() returns at
// once, and the exception program runs when the ray-generation program returns.
LUCENT_HD void raise_exception(int code, unsigned detail);
/// Per-thread scratch that an out-of-bounds access reads and writes instead of memory.
LUCENT_HD void* out_of_bounds_scratch();
#else
[[noreturn]] void raise_exception(int code, unsigned detail);
#endif
LUCENT_HD bool print_enabled_here();
LUCENT_HD void print_text(const char* text);
}  // namespace detail

/// Index of this invocation in the launch grid.
LUCENT_HD uint3 launch_index();
/// Size of the launch grid (unused dimensions are 1).
LUCENT_HD uint3 launch_size();
/// This launch index's own TEA key (Sebald, Fig. 4): generate_tea_key(zafar_tea_key(),
/// (slot, seed)) for the device slot the index belongs to (device_slot_of) and the
/// Context's random seed. Streams differ per device of the Context's list; one device: slot 0.
LUCENT_HD uint4 device_tea_key();
/// The ray being traced, in the space of the current program (object space in
/// intersection, any-hit and visit programs below a Transform; world space elsewhere).
LUCENT_HD const Ray& current_ray();
/// The current ray's time (OptiX's optixGetRayTime): the `time` its trace() or occluded()
/// was given, at which moving geometry and motion transforms were intersected. 0 outside a
/// trace. Pass it on to secondary rays (make_ray's `time`) so they see the same instant.
LUCENT_HD float ray_time();
/// Parametric distance of the current hit (closest so far inside intersection programs).
LUCENT_HD float t_hit();
/// Primitive index of the current hit, or of the primitive being intersected.
LUCENT_HD unsigned primitive_index();

/// Trace a ray against the graph below `root`; the payload type must match the ray type's.
/// `ray_flags` (RayFlags, or'ed) control any-hit, closest hit, termination and culling for
/// this ray; the ray visits only the nodes and geometry instances whose visibility mask
/// shares a bit with `visibility_mask` (0 visits nothing). Contradicting flags (two of
/// kRayFlagsAnyHitChoice, both facing culls) or a mask above 0xff raise
/// kExceptionInvalidRayFlags.
/// A module that passes them declares so: LUCENT_MODULE(name, lucent::kUsesRayFlags).
#if defined(__CUDACC_RTC__) && defined(LUCENT_GPU_RAY_CONTROL) && !LUCENT_GPU_RAY_CONTROL
// No module of this megakernel declares kUsesRayFlags and the scene has no masks, ids or
// opaque geometry: the megakernel has no per-ray control, and a call with flags is a
// compile error that says what to declare.
template <class Payload>
__device__ void trace(Handle, const Ray&, Payload&, unsigned, unsigned = kVisibilityMaskAll) {
    static_assert(detail::dependent_false<Payload>,
                  "trace() with ray flags or a visibility mask is called by a module that "
                  "does not declare it: write LUCENT_MODULE(name, lucent::kUsesRayFlags)");
}
/// trace() with no ray flags, visiting everything.
template <class Payload>
LUCENT_HD void trace(Handle root, const Ray& ray, Payload& payload) {
    detail::trace_erased(root, ray, &payload,
                         reinterpret_cast<const void*>(sizeof(Payload) << 8 | alignof(Payload)),
                         kRayFlagNone, kVisibilityMaskAll);
}
#else
template <class Payload>
LUCENT_HD void trace(Handle root, const Ray& ray, Payload& payload, unsigned ray_flags,
                     unsigned visibility_mask = kVisibilityMaskAll) {
#if LUCENT_GPU_CODE
    // No type identity without RTTI on the GPU: size and alignment catch most mismatches.
    detail::trace_erased(root, ray, &payload,
                         reinterpret_cast<const void*>(sizeof(Payload) << 8 | alignof(Payload)),
                         ray_flags, visibility_mask);
#else
    detail::trace_fields(root, ray.origin, ray.direction, ray.tmin, ray.tmax, ray.ray_type,
                         ray.time, &payload, &detail::TypeTag<Payload>::id, ray_flags, visibility_mask);
#endif
}
/// trace() with no ray flags, visiting everything.
template <class Payload>
LUCENT_HD void trace(Handle root, const Ray& ray, Payload& payload) {
    trace(root, ray, payload, kRayFlagNone, kVisibilityMaskAll);
}
#endif

/// What occluded() counts as blocking a ray.
enum class Occlusion : unsigned {
    /// The primitives themselves: built-in triangles by the watertight test, custom
    /// primitives by their intersection programs.
    kExact = 0,
    /// Built-in triangles by the boxes of their BVH's leaves, conservatively: a leaf blocks
    /// the ray when the ray passes wholly through its box within (tmin, tmax); a leaf box
    /// that holds either end of the ray does not, or every surface would shadow itself. The
    /// imperfect visibility of Marques and Santos (IGI paper §4.1), with the triangles' boxes
    /// taken a leaf (up to eight triangles) at a time from the BVH the scene already has:
    /// no second graph, and no triangle is ever loaded. Custom primitives are tested exactly.
    kLeafBoxes = 1,
};

/// A shadow query: true when anything in the graph below `root` intersects `ray` within
/// (tmin, tmax). No program runs but intersection programs: every primitive counts as
/// opaque (any-hit programs are skipped), there is no closest hit and no miss, and traversal
/// stops at the first intersection found (OptiX's terminate-on-first-hit with any-hit
/// disabled). `ray.ray_type` must be a valid ray type; selectors' visit programs see it.
/// `test` says what blocks the ray: the primitives (kExact) or, for approximate
/// visibility, the BVH's leaf boxes (kLeafBoxes).
/// Use it where a shadow any-hit would only say "blocked"; shadows that attenuate (glass)
/// need trace() with an any-hit program. Much cheaper than trace(): on a GeometryGroup of
/// triangles it is the bare any-hit traversal of the BVH.
/// `ray_flags` may cull facing triangles (kRayFlagCullBackFacingTriangles,
/// kRayFlagCullFrontFacingTriangles; not with kLeafBoxes, which loads no triangle) and may
/// name what occluded() does anyway (kRayFlagDisableAnyHit, kRayFlagTerminateOnFirstHit,
/// kRayFlagDisableClosestHit); the other any-hit flags raise kExceptionInvalidRayFlags.
/// `visibility_mask` is trace()'s. With kLeafBoxes, the masks of geometry instances inside
/// a GeometryGroup make it test that group exactly (a leaf box mixes instances).
/// A module that calls it declares so: LUCENT_MODULE(name, lucent::kUsesOccluded).
#if defined(__CUDACC_RTC__) && defined(LUCENT_GPU_OCCLUSION) && !LUCENT_GPU_OCCLUSION
// No module of this megakernel declares kUsesOccluded, so the traversal has no occlusion
// path: a call is a compile error that says what to declare.
template <class Undeclared = void>
__device__ bool occluded(Handle, const Ray&, Occlusion = Occlusion::kExact,
                         unsigned = kRayFlagNone, unsigned = kVisibilityMaskAll) {
    static_assert(detail::dependent_false<Undeclared>,
                  "occluded() is called by a module that does not declare it: write "
                  "LUCENT_MODULE(name, lucent::kUsesOccluded)");
    return false;
}
#elif defined(__CUDACC_RTC__) && defined(LUCENT_GPU_RAY_CONTROL) && !LUCENT_GPU_RAY_CONTROL
// No per-ray control in this megakernel (see trace()): occluded() takes no flags.
__device__ __forceinline__ bool occluded(Handle root, const Ray& ray,
                                         Occlusion test = Occlusion::kExact);
template <class Undeclared = void>
__device__ bool occluded(Handle, const Ray&, Occlusion, unsigned,
                         unsigned = kVisibilityMaskAll) {
    static_assert(detail::dependent_false<Undeclared>,
                  "occluded() with ray flags or a visibility mask is called by a module that "
                  "does not declare it: write LUCENT_MODULE(name, lucent::kUsesOccluded, "
                  "lucent::kUsesRayFlags)");
    return false;
}
#elif defined(__CUDACC_RTC__)
// In the megakernel the runtime defines it, inlined into each caller: its fast path is the
// bare BVH traversal, and a call would cost the ABI's register saves on every shadow ray.
__device__ __forceinline__ bool occluded(Handle root, const Ray& ray,
                                         Occlusion test = Occlusion::kExact,
                                         unsigned ray_flags = kRayFlagNone,
                                         unsigned visibility_mask = kVisibilityMaskAll);
#elif LUCENT_GPU_CODE
LUCENT_HD bool occluded(Handle root, const Ray& ray, Occlusion test = Occlusion::kExact,
                        unsigned ray_flags = kRayFlagNone,
                        unsigned visibility_mask = kVisibilityMaskAll);
#else
inline bool occluded(Handle root, const Ray& ray, Occlusion test = Occlusion::kExact,
                     unsigned ray_flags = kRayFlagNone,
                     unsigned visibility_mask = kVisibilityMaskAll) {
    return detail::occluded_fields(root, ray.origin, ray.direction, ray.tmin, ray.tmax,
                                   ray.ray_type, ray.time, unsigned(test), ray_flags,
                                   visibility_mask);
}
#endif

// ---- deferred rays: traced before the launch ends, not before the call returns ---------------
// A ray-generation program that only hands a ray's answer on (to an output buffer, through
// its hit programs) need not wait for it. trace_deferred() and occluded_deferred() queue
// the ray and return at once; the ray is traced, and its programs run, before the launch
// ends. On the CPU a worker's queued rays, tens of thousands from many launch indices, are
// traced together as ray streams (many rays through each BVH node at once, Barringer and
// Akenine-Möller 2014): what makes incoherent rays fast there, where trace() has to finish
// one ray's walk before the program can go on. On the GPU a warp already traces 32 rays
// together, and each is traced at once, as trace() traces it.
// - What the ray's programs write must live in a buffer: the caller has returned when they
//   run. The CPU backend refuses a local variable of the program (lucent::Error).
// - Only a ray-generation program's rays wait; called from any other program (closest hit,
//   miss, exception) these are trace() and occluded().
// - Their programs see the deferring launch index (launch_index()); an exception raised in
//   them ends that ray's programs and runs the entry point's exception program for that
//   index. The order in which deferred rays' programs run is unspecified.
// - No ray flags or visibility mask: a deferred ray visits everything.
#if !LUCENT_GPU_CODE
namespace detail {
void trace_deferred_fields(Handle root, float3 origin, float3 direction, float tmin, float tmax,
                           unsigned ray_type, float time, void* payload,
                           const void* payload_tag);
void occluded_deferred_fields(Handle root, float3 origin, float3 direction, float tmin,
                              float tmax, unsigned ray_type, float time, unsigned occlusion,
                              void* flag, void (*write_flag)(void*, bool));
}  // namespace detail
#endif

/// trace() without waiting: `ray` is traced against the graph below `root` before the
/// launch ends, and its closest-hit or miss program runs then on `payload`, which must live
/// in a buffer (an element of an output buffer, as `rec.hits[i]`). The payload type must
/// match the ray type's, as in trace(); trace()'s checks raise their exceptions now.
template <class Payload>
LUCENT_HD void trace_deferred(Handle root, const Ray& ray, Payload& payload) {
#if LUCENT_GPU_CODE
    trace(root, ray, payload);
#else
    detail::trace_deferred_fields(root, ray.origin, ray.direction, ray.tmin, ray.tmax,
                                  ray.ray_type, ray.time, &payload,
                                  &detail::TypeTag<Payload>::id);
#endif
}

/// occluded() without waiting: before the launch ends, `blocked` (in a buffer, as
/// trace_deferred()'s payload) becomes 1 when anything below `root` intersects `ray` within
/// (tmin, tmax), else 0. `test` as in occluded(); the module declares kUsesOccluded.
#if defined(__CUDACC_RTC__) && defined(LUCENT_GPU_OCCLUSION) && !LUCENT_GPU_OCCLUSION
template <class Flag>
__device__ void occluded_deferred(Handle, const Ray&, Flag&, Occlusion = Occlusion::kExact) {
    static_assert(detail::dependent_false<Flag>,
                  "occluded_deferred() is called by a module that does not declare it: write "
                  "LUCENT_MODULE(name, lucent::kUsesOccluded)");
}
#else
template <class Flag>
LUCENT_HD void occluded_deferred(Handle root, const Ray& ray, Flag& blocked,
                                 Occlusion test = Occlusion::kExact) {
#if LUCENT_GPU_CODE
    blocked = Flag(occluded(root, ray, test) ? 1 : 0);
#else
    detail::occluded_deferred_fields(root, ray.origin, ray.direction, ray.tmin, ray.tmax,
                                     ray.ray_type, ray.time, unsigned(test), &blocked,
                                     [](void* flag, bool b) { *static_cast<Flag*>(flag) = Flag(b ? 1 : 0); });
#endif
}
#endif

/// In an intersection program: is t inside the ray's current interval (tmin, closest hit so
/// far)? False, and no effect, in every other program kind.
LUCENT_HD bool potential_intersection(float t);
/// In an intersection program, after potential_intersection(t) returned true and the
/// attributes were written: commit the hit with this material index (runs any-hit).
/// Returns false when any-hit ignored it, when no candidate is open, and outside an
/// intersection program. An index beyond the instance's materials raises
/// kExceptionMaterialIndexOutOfRange (detail: the index).
LUCENT_HD bool report_intersection(unsigned material_index);

// ---- ending an any-hit program -------------------------------------------------------------
// ignore_intersection() and terminate_ray() end the any-hit program that calls them, as in
// OptiX: code after them does not run. Device code has neither exceptions nor longjmp, so
// they are macros that record the outcome and `return` from the program. They compile only
// in the body of a LUCENT_ANY_HIT program, whose hidden parameter `lucent_any_hit_scope`
// they name; elsewhere (another program kind, a helper function) the global declaration
// below is found instead, and a static_assert says what to do. Write them unqualified.
// Inside a lambda in the body they would end the lambda only: do not call them there.
/// The type of an any-hit program's hidden last parameter.
struct AnyHitScope {};
namespace detail {
/// How an any-hit program ended (what the runtime reads after it returns).
enum class AnyHitOutcome : unsigned {
    kAccept,     // it returned
    kIgnore,     // ignore_intersection()
    kTerminate,  // terminate_ray()
};
/// Records the outcome in the innermost trace (nothing outside a trace).
LUCENT_HD void end_any_hit(AnyHitOutcome outcome);
struct OutsideAnyHit {};
template <class Scope>
struct IsAnyHitScope {
    static constexpr bool value = false;
};
template <>
struct IsAnyHitScope<AnyHitScope> {
    static constexpr bool value = true;
};
template <class Scope>
LUCENT_HD inline void end_any_hit_in(AnyHitOutcome outcome) {
    static_assert(IsAnyHitScope<Scope>::value,
                  "ignore_intersection() and terminate_ray() end an any-hit program: call them "
                  "in the body of a LUCENT_ANY_HIT program. A helper function cannot end its "
                  "caller: return a flag from it and call them in the program.");
    end_any_hit(outcome);
}
}  // namespace detail
}  // namespace lucent

/// Found outside the body of an any-hit program (only its type is ever used).
extern const ::lucent::detail::OutsideAnyHit lucent_any_hit_scope;

/// In an any-hit program: discard this intersection and go on traversing; ends the program.
#define ignore_intersection()                                                                  \
    do {                                                                                       \
        ::lucent::detail::end_any_hit_in<decltype(lucent_any_hit_scope)>(                     \
            ::lucent::detail::AnyHitOutcome::kIgnore);                                         \
        return;                                                                                \
    } while (0)
/// In an any-hit program: accept this intersection and stop the traversal of this ray
/// (closest hit still runs); ends the program.
#define terminate_ray()                                                                        \
    do {                                                                                       \
        ::lucent::detail::end_any_hit_in<decltype(lucent_any_hit_scope)>(                     \
            ::lucent::detail::AnyHitOutcome::kTerminate);                                      \
        return;                                                                                \
    } while (0)

namespace lucent {

namespace detail {
/// The transform in effect for the running program (the committed hit's in closest hit,
/// the traversal position's in intersection, any-hit, attribute and visit programs); false
/// when there is none. Each backend implements it.
LUCENT_HD bool current_transform(const Matrix4x3*& to_world, const Matrix4x3*& to_object);
}  // namespace detail

/// The user id (Transform::set_instance_id) of the innermost Transform above the committed
/// hit in closest hit, above the traversal position in intersection, any-hit and attribute
/// programs (OptiX's optixGetInstanceId); 0 when there is no Transform, and elsewhere.
LUCENT_HD unsigned instance_id();
/// The user id of the hit's GeometryInstance (GeometryInstance::set_instance_id) in closest
/// hit, of the one being intersected in intersection, any-hit and attribute programs; 0
/// elsewhere.
LUCENT_HD unsigned geometry_instance_id();

/// Object/world transforms of the current hit or traversal position.
LUCENT_HD inline float3 object_to_world_point(float3 p) {
    const Matrix4x3 *w, *o;
    return detail::current_transform(w, o) ? transform_point(*w, p) : p;
}
LUCENT_HD inline float3 object_to_world_vector(float3 v) {
    const Matrix4x3 *w, *o;
    return detail::current_transform(w, o) ? transform_vector(*w, v) : v;
}
LUCENT_HD inline float3 object_to_world_normal(float3 n) {
    const Matrix4x3 *w, *o;
    return detail::current_transform(w, o) ? transform_normal_by_inverse(*o, n) : n;
}
LUCENT_HD inline float3 world_to_object_point(float3 p) {
    const Matrix4x3 *w, *o;
    return detail::current_transform(w, o) ? transform_point(*o, p) : p;
}
LUCENT_HD inline float3 world_to_object_vector(float3 v) {
    const Matrix4x3 *w, *o;
    return detail::current_transform(w, o) ? transform_vector(*o, v) : v;
}
LUCENT_HD inline float3 world_to_object_normal(float3 n) {
    const Matrix4x3 *w, *o;
    return detail::current_transform(w, o) ? transform_normal_by_inverse(*w, n) : n;
}
/// The whole matrices (the identity when not below a Transform): OptiX's
/// optixGetObjectToWorldTransformMatrix and optixGetWorldToObjectTransformMatrix.
LUCENT_HD inline Matrix4x3 object_to_world_matrix() {
    const Matrix4x3 *w, *o;
    return detail::current_transform(w, o) ? *w : identity_matrix();
}
LUCENT_HD inline Matrix4x3 world_to_object_matrix() {
    const Matrix4x3 *w, *o;
    return detail::current_transform(w, o) ? *o : identity_matrix();
}

/// Raise a user exception: code must be >= kUserExceptionBase. Ends this launch index
/// and calls the entry point's exception program.
#if !LUCENT_GPU_CODE
[[noreturn]]
#endif
LUCENT_HD inline void
throw_exception(int code, unsigned detail = 0) {
    detail::raise_exception(code < kUserExceptionBase ? kUserExceptionBase : code, detail);
}

/// printf-style output, shown only when printing is enabled on the context (and, if
/// a print launch index is set, only from that index).
template <class... Args>
LUCENT_HD void print(const char* format, Args... args) {
#if LUCENT_GPU_CODE
    if (detail::print_enabled_here()) printf(format, args...);
#else
    if (!detail::print_enabled_here()) return;
    char text[1024];
    if constexpr (sizeof...(Args) == 0) {
        std::snprintf(text, sizeof text, "%s", format);
    } else {
        std::snprintf(text, sizeof text, format, args...);
    }
    detail::print_text(text);
#endif
}

// ---- buffer access with bounds checks --------------------------------------
template <class T>
LUCENT_HD T& BufferView<T>::out_of_bounds(unsigned linear) const {
    detail::raise_exception(kExceptionBufferIndexOutOfBounds, linear);
#if LUCENT_GPU_CODE
    return *static_cast<T*>(detail::out_of_bounds_scratch());
#endif
}
// Megakernels of scenes with exceptions off are generated without the checks.
#if LUCENT_GPU_CODE && defined(LUCENT_GPU_EXCEPTIONS) && !LUCENT_GPU_EXCEPTIONS
#define LUCENT_BOUNDS_CHECKED(flags) false
#else
#define LUCENT_BOUNDS_CHECKED(flags) ((flags)&kViewBoundsChecked)
#endif
template <class T>
LUCENT_HD T& BufferView<T>::operator[](unsigned i) const {
    if (LUCENT_BOUNDS_CHECKED(flags) && i >= count()) return out_of_bounds(i);
    return data[i];
}
template <class T>
LUCENT_HD T& BufferView<T>::operator[](uint2 i) const {
    if (LUCENT_BOUNDS_CHECKED(flags) && (i.x >= size.x || i.y >= size.y))
        return out_of_bounds(i.y * size.x + i.x);
    return data[i.y * size.x + i.x];
}
template <class T>
LUCENT_HD T& BufferView<T>::operator[](uint3 i) const {
    if (LUCENT_BOUNDS_CHECKED(flags) && (i.x >= size.x || i.y >= size.y || i.z >= size.z))
        return out_of_bounds((i.z * size.y + i.y) * size.x + i.x);
    return data[(i.z * size.y + i.y) * size.x + i.x];
}

// ---- textures ----------------------------------------------------------------
namespace detail {
LUCENT_HD inline int wrap_texel(int i, int n, WrapMode mode) {
    switch (mode) {
        case WrapMode::kClampToEdge:
            return i < 0 ? 0 : (i >= n ? n - 1 : i);
        case WrapMode::kMirror: {
            int period = 2 * n;
            int m = i % period;
            if (m < 0) m += period;
            return m < n ? m : period - 1 - m;
        }
        case WrapMode::kRepeat:
        default: {
            int m = i % n;
            return m < 0 ? m + n : m;
        }
    }
}
LUCENT_HD inline float4 fetch_texel(const TextureView& t, int x, int y) {
    x = wrap_texel(x, int(t.width), t.wrap_u);
    y = wrap_texel(y, int(t.height), t.wrap_v);
    return t.texels[unsigned(y) * t.width + unsigned(x)];
}
}  // namespace detail

/// Sample a texture at uv (texel centres at (i + 0.5) / size), bilinear or nearest.
LUCENT_HD inline float4 tex2D(const TextureView& t, float2 uv) {
    float x = uv.x * float(t.width) - 0.5f;
    float y = uv.y * float(t.height) - 0.5f;
    float fx = floorf(x), fy = floorf(y);
    int ix = int(fx), iy = int(fy);
    if (t.filter == FilterMode::kNearest)
        return detail::fetch_texel(t, int(floorf(x + 0.5f)), int(floorf(y + 0.5f)));
    float ax = x - fx, ay = y - fy;
    float4 a = detail::fetch_texel(t, ix, iy), b = detail::fetch_texel(t, ix + 1, iy);
    float4 c = detail::fetch_texel(t, ix, iy + 1), d = detail::fetch_texel(t, ix + 1, iy + 1);
    return (a * (1 - ax) + b * ax) * (1 - ay) + (c * (1 - ax) + d * ax) * ay;
}

}  // namespace lucent

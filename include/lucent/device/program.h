// One macro per program kind (OptiX paper §3.1). Each defines the program as a plain
// function and, on the host, registers a ProgramDesc naming its record, payload and
// attribute types, so the host can look the program up by name and type-check it.
//
// Inside the body the parameters are always named:
//   rec  — the program's record (its resolved variables), const
//   prd  — the ray payload (miss, closest hit, any hit)
//   attr — the hit attributes (written by intersection/attribute, read by hit programs)
//   prim — the primitive index (intersection, bounding box, attribute)
//   box  — the box to fill (bounding box);  ex — the exception (exception programs)
#pragma once

#include "lucent/device/api.h"
#include "lucent/device/module.h"
#include "lucent/device/reflect.h"

// Attributes live in the engine's fixed scratch space, on both backends (OptiX counts 8
// 32-bit attribute registers; Lucent allows kMaxAttributeBytes). Payloads have no limit of
// their own: trace() passes the caller's payload object by address.
#define LUCENT_CHECK_ATTRIBUTES_(name, Attributes)                                          \
    static_assert(sizeof(Attributes) <= ::lucent::kMaxAttributeBytes,                       \
                  "the attribute type of program '" #name "' is larger than "               \
                  "lucent::kMaxAttributeBytes (256 bytes): keep attributes small and put "  \
                  "large per-hit data in the payload or a buffer")

#if !LUCENT_GPU_CODE
#include <string_view>

namespace lucent {

enum class ProgramKind {
    kRayGeneration,
    kException,
    kMiss,
    kIntersection,
    kBoundingBox,
    kClosestHit,
    kAnyHit,
    kVisit,
    kAttribute,
    kCallable,
};
const char* program_kind_name(ProgramKind kind);

/// What the host knows of a program: its kind and types, and its entry point.
struct ProgramDesc {
    std::string_view name;
    ProgramKind kind;
    const char* file;
    const RecordInfo* record;
    const TypeInfo* payload;     // miss, closest hit, any hit
    const TypeInfo* attributes;  // intersection, attribute, closest hit, any hit
    const TypeInfo* signature;   // callables: R(Args...)
    void (*entry)();             // the thunk; its real type follows from `kind`
    std::string_view scope;      // enclosing namespaces, "" or "ns::inner::"
    const ModuleInfo* module = nullptr;  // the module whose LUCENT_MODULE the program is in
    void (*function)() = nullptr;        // the program's own function (LUCENT_PROGRAM lookup)
};

// Thunk signatures per kind (records, payloads and attributes type-erased).
using RayGenerationFn = void (*)(const void* rec);
using ExceptionFn = void (*)(const void* rec, const ExceptionInfo& ex);
using MissFn = void (*)(const void* rec, void* prd);
using HitFn = void (*)(const void* rec, void* prd, const void* attr);
using IntersectionFn = void (*)(const void* rec, unsigned prim, void* attr);
using BoundingBoxFn = void (*)(const void* rec, unsigned prim, Aabb& box);
using VisitFn = unsigned (*)(const void* rec);
using AttributeFn = void (*)(const void* rec, unsigned prim, float2 barycentrics, void* attr);

namespace detail {
/// Sets desc.scope from the __PRETTY_FUNCTION__ of the descriptor function the macro
/// defines beside the program ("... ns::lucent_program_desc_name()"), so code generated for
/// the GPU can name the program as ::ns::name.
inline ProgramDesc with_scope(ProgramDesc desc, std::string_view pretty) {
    size_t at = pretty.find("lucent_program_desc_");
    size_t begin = pretty.rfind(' ', at);
    begin = begin == std::string_view::npos ? 0 : begin + 1;
    desc.scope =
        at == std::string_view::npos ? std::string_view() : pretty.substr(begin, at - begin);
    return desc;
}

template <class F>
void (*erase_fn(F f))() {
    return reinterpret_cast<void (*)()>(f);
}
/// Places a program's description in its module, with its function's address.
inline ProgramDesc in_module(ProgramDesc desc, const ModuleInfo& module, void (*function)()) {
    desc.module = &module;
    desc.function = function;
    return desc;
}
template <class Record>
ProgramDesc make_desc(std::string_view name, ProgramKind kind, const char* file,
                      const TypeInfo* payload, const TypeInfo* attributes, void (*entry)(),
                      const TypeInfo* signature = nullptr) {
    return ProgramDesc{name,    kind,       file,      &record_info_of<Record>(),
                       payload, attributes, signature, entry};
}
template <class F>
struct CallableSignature;
template <class R, class Rec, class... Args>
struct CallableSignature<R (*)(const Rec&, Args...)> {
    using type = R(Args...);
};
}  // namespace detail
}  // namespace lucent

// Each program's description lives in a function-local static (one per binary however many
// files include the module) and is added to the module that lucent_this_module() finds by
// ordinary name lookup: the LUCENT_MODULE of the enclosing namespace.
#define LUCENT_DECLARE_PROGRAM_(name, make)                                             \
    inline const ::lucent::ProgramDesc& lucent_program_desc_##name() {                  \
        static const ::lucent::ProgramDesc desc = ::lucent::detail::in_module(          \
            ::lucent::detail::with_scope(make, __PRETTY_FUNCTION__), lucent_this_module(), \
            ::lucent::detail::erase_fn(&name));                                         \
        return desc;                                                                    \
    }                                                                                   \
    inline const bool lucent_program_registered_##name =                                \
        lucent_this_module().add(lucent_program_desc_##name());

#define LUCENT_RAY_GENERATION(name, Record)                                                       \
    inline void name(const Record& rec);                                                          \
    LUCENT_DECLARE_PROGRAM_(                                                                      \
        name, ::lucent::detail::make_desc<Record>(#name, ::lucent::ProgramKind::kRayGeneration,   \
                                                  __FILE__, nullptr, nullptr,                     \
                                                  ::lucent::detail::erase_fn(+[](const void* r) { \
                                                      name(*static_cast<const Record*>(r));       \
                                                  })))                                            \
    inline void name([[maybe_unused]] const Record& rec)

#define LUCENT_EXCEPTION(name, Record)                                                        \
    inline void name(const Record& rec, const ::lucent::ExceptionInfo& ex);                   \
    LUCENT_DECLARE_PROGRAM_(                                                                  \
        name,                                                                                 \
        ::lucent::detail::make_desc<Record>(                                                  \
            #name, ::lucent::ProgramKind::kException, __FILE__, nullptr, nullptr,             \
            ::lucent::detail::erase_fn(+[](const void* r, const ::lucent::ExceptionInfo& e) { \
                name(*static_cast<const Record*>(r), e);                                      \
            })))                                                                              \
    inline void name([[maybe_unused]] const Record& rec,                                      \
                     [[maybe_unused]] const ::lucent::ExceptionInfo& ex)

#define LUCENT_MISS(name, Record, Payload)                                                     \
    inline void name(const Record& rec, Payload& prd);                                         \
    LUCENT_DECLARE_PROGRAM_(                                                                   \
        name,                                                                                  \
        ::lucent::detail::make_desc<Record>(                                                   \
            #name, ::lucent::ProgramKind::kMiss, __FILE__, &::lucent::type_info_of<Payload>(), \
            nullptr, ::lucent::detail::erase_fn(+[](const void* r, void* p) {                  \
                name(*static_cast<const Record*>(r), *static_cast<Payload*>(p));               \
            })))                                                                               \
    inline void name([[maybe_unused]] const Record& rec, [[maybe_unused]] Payload& prd)

#define LUCENT_HIT_PROGRAM_(name, Kind, Record, Payload, Attributes)                         \
    inline void name(const Record& rec, Payload& prd, const Attributes& attr);               \
    LUCENT_DECLARE_PROGRAM_(                                                                 \
        name, ::lucent::detail::make_desc<Record>(                                           \
                  #name, ::lucent::ProgramKind::Kind, __FILE__,                              \
                  &::lucent::type_info_of<Payload>(), &::lucent::type_info_of<Attributes>(), \
                  ::lucent::detail::erase_fn(+[](const void* r, void* p, const void* a) {    \
                      name(*static_cast<const Record*>(r), *static_cast<Payload*>(p),        \
                           *static_cast<const Attributes*>(a));                              \
                  })))                                                                       \
    inline void name([[maybe_unused]] const Record& rec, [[maybe_unused]] Payload& prd,      \
                     [[maybe_unused]] const Attributes& attr)

#define LUCENT_CLOSEST_HIT(name, Record, Payload, Attributes) \
    LUCENT_HIT_PROGRAM_(name, kClosestHit, Record, Payload, Attributes)
/// Any-hit programs have a hidden last parameter, `lucent_any_hit_scope`: what lets
/// ignore_intersection() and terminate_ray() compile in their body only (lucent/device/api.h).
#define LUCENT_ANY_HIT(name, Record, Payload, Attributes)                                       \
    inline void name(const Record& rec, Payload& prd, const Attributes& attr,                   \
                     ::lucent::AnyHitScope = {});                                               \
    LUCENT_DECLARE_PROGRAM_(                                                                    \
        name, ::lucent::detail::make_desc<Record>(                                              \
                  #name, ::lucent::ProgramKind::kAnyHit, __FILE__,                              \
                  &::lucent::type_info_of<Payload>(), &::lucent::type_info_of<Attributes>(),    \
                  ::lucent::detail::erase_fn(+[](const void* r, void* p, const void* a) {       \
                      name(*static_cast<const Record*>(r), *static_cast<Payload*>(p),           \
                           *static_cast<const Attributes*>(a));                                 \
                  })))                                                                          \
    inline void name([[maybe_unused]] const Record& rec, [[maybe_unused]] Payload& prd,         \
                     [[maybe_unused]] const Attributes& attr,                                   \
                     [[maybe_unused]] ::lucent::AnyHitScope lucent_any_hit_scope)

#define LUCENT_INTERSECTION(name, Record, Attributes)                                        \
    LUCENT_CHECK_ATTRIBUTES_(name, Attributes);                                              \
    inline void name(const Record& rec, unsigned prim, Attributes& attr);                    \
    LUCENT_DECLARE_PROGRAM_(                                                                 \
        name, ::lucent::detail::make_desc<Record>(                                           \
                  #name, ::lucent::ProgramKind::kIntersection, __FILE__, nullptr,            \
                  &::lucent::type_info_of<Attributes>(),                                     \
                  ::lucent::detail::erase_fn(+[](const void* r, unsigned i, void* a) {       \
                      name(*static_cast<const Record*>(r), i, *static_cast<Attributes*>(a)); \
                  })))                                                                       \
    inline void name([[maybe_unused]] const Record& rec, [[maybe_unused]] unsigned prim,     \
                     [[maybe_unused]] Attributes& attr)

#define LUCENT_BOUNDING_BOX(name, Record)                                                        \
    inline void name(const Record& rec, unsigned prim, ::lucent::Aabb& box);                     \
    LUCENT_DECLARE_PROGRAM_(                                                                     \
        name, ::lucent::detail::make_desc<Record>(                                               \
                  #name, ::lucent::ProgramKind::kBoundingBox, __FILE__, nullptr, nullptr,        \
                  ::lucent::detail::erase_fn(+[](const void* r, unsigned i, ::lucent::Aabb& b) { \
                      name(*static_cast<const Record*>(r), i, b);                                \
                  })))                                                                           \
    inline void name([[maybe_unused]] const Record& rec, [[maybe_unused]] unsigned prim,         \
                     ::lucent::Aabb& box)

/// Selector visit program: returns the index of the child the current ray traverses
/// (an index >= the child count means none).
#define LUCENT_VISIT(name, Record)                                                                \
    inline unsigned name(const Record& rec);                                                      \
    LUCENT_DECLARE_PROGRAM_(name,                                                                 \
                            ::lucent::detail::make_desc<Record>(                                  \
                                #name, ::lucent::ProgramKind::kVisit, __FILE__, nullptr, nullptr, \
                                ::lucent::detail::erase_fn(+[](const void* r) -> unsigned {       \
                                    return name(*static_cast<const Record*>(r));                  \
                                })))                                                              \
    inline unsigned name([[maybe_unused]] const Record& rec)

/// Attribute program of built-in triangles: turns barycentrics into user attributes,
/// run once for the closest hit (and for each any-hit candidate).
#define LUCENT_ATTRIBUTE(name, Record, Attributes)                                               \
    LUCENT_CHECK_ATTRIBUTES_(name, Attributes);                                                  \
    inline void name(const Record& rec, unsigned prim, float2 barycentrics, Attributes& attr);   \
    LUCENT_DECLARE_PROGRAM_(                                                                     \
        name, ::lucent::detail::make_desc<Record>(                                               \
                  #name, ::lucent::ProgramKind::kAttribute, __FILE__, nullptr,                   \
                  &::lucent::type_info_of<Attributes>(),                                         \
                  ::lucent::detail::erase_fn(+[](const void* r, unsigned i, float2 b, void* a) { \
                      name(*static_cast<const Record*>(r), i, b, *static_cast<Attributes*>(a));  \
                  })))                                                                           \
    inline void name([[maybe_unused]] const Record& rec, [[maybe_unused]] unsigned prim,         \
                     [[maybe_unused]] float2 barycentrics, [[maybe_unused]] Attributes& attr)

/// Callable program: LUCENT_CALLABLE(name, Record, float3, (float3 n, float t)) { ... }
/// Bound to a record field of type Callable<float3(float3, float)> through a variable.
#define LUCENT_CALLABLE(name, Record, Result, Params)                                          \
    inline Result name(const Record& rec, LUCENT_UNPAREN_ Params);                             \
    LUCENT_DECLARE_PROGRAM_(                                                                   \
        name, ::lucent::detail::make_desc<Record>(                                             \
                  #name, ::lucent::ProgramKind::kCallable, __FILE__, nullptr, nullptr,         \
                  ::lucent::detail::erase_fn(::lucent::detail::callable_thunk<&name>(&name)),  \
                  &::lucent::type_info_of<                                                     \
                      typename ::lucent::detail::CallableSignature<decltype(&name)>::type>())) \
    inline Result name([[maybe_unused]] const Record& rec, LUCENT_UNPAREN_ Params)

#define LUCENT_UNPAREN_(...) __VA_ARGS__

namespace lucent::detail {
template <auto F, class Record, class R, class... Args>
R callable_thunk_impl(const void* rec, Args... args) {
    return F(*static_cast<const Record*>(rec), args...);
}
/// Wraps `R F(const Record&, Args...)` as `R thunk(const void*, Args...)` (Callable's fn).
template <auto F, class Record, class R, class... Args>
constexpr auto callable_thunk(R (*)(const Record&, Args...)) -> R (*)(const void*, Args...) {
    return &callable_thunk_impl<F, Record, R, Args...>;
}
}  // namespace lucent::detail

#else  // GPU code: programs are plain device functions; the JIT generates dispatch.
#define LUCENT_RAY_GENERATION(name, Record) __device__ void name(const Record& rec)
#define LUCENT_EXCEPTION(name, Record) \
    __device__ void name(const Record& rec, const ::lucent::ExceptionInfo& ex)
#define LUCENT_MISS(name, Record, Payload) __device__ void name(const Record& rec, Payload& prd)
#define LUCENT_CLOSEST_HIT(name, Record, Payload, Attributes) \
    __device__ void name(const Record& rec, Payload& prd, const Attributes& attr)
#define LUCENT_ANY_HIT(name, Record, Payload, Attributes)                          \
    __device__ void name(const Record& rec, Payload& prd, const Attributes& attr, \
                         [[maybe_unused]] ::lucent::AnyHitScope lucent_any_hit_scope = {})
#define LUCENT_INTERSECTION(name, Record, Attributes) \
    LUCENT_CHECK_ATTRIBUTES_(name, Attributes);       \
    __device__ void name(const Record& rec, unsigned prim, Attributes& attr)
#define LUCENT_BOUNDING_BOX(name, Record) \
    __device__ void name(const Record& rec, unsigned prim, ::lucent::Aabb& box)
#define LUCENT_VISIT(name, Record) __device__ unsigned name(const Record& rec)
#define LUCENT_ATTRIBUTE(name, Record, Attributes) \
    LUCENT_CHECK_ATTRIBUTES_(name, Attributes);    \
    __device__ void name(const Record& rec, unsigned prim, float2 barycentrics, Attributes& attr)
#define LUCENT_UNPAREN_(...) __VA_ARGS__
#define LUCENT_CALLABLE(name, Record, Result, Params) \
    __device__ Result name(const Record& rec, LUCENT_UNPAREN_ Params)
#endif

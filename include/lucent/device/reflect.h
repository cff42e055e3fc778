// Name reflection for records (a program's variables), payloads and attributes.
// Host side only: GPU builds see the macros expand to nothing.
#pragma once

#include "lucent/device/api.h"

#if !LUCENT_GPU_CODE
#include <cstddef>
#include <string_view>
#include <type_traits>
#include <vector>

namespace lucent {

/// Identity of a C++ type as the host checks it: readable name, size, alignment,
/// and the address the device API uses for the same type (detail::TypeTag). Compare two
/// with same_type(): a module compiled at run time has TypeInfos of its own.
struct TypeInfo {
    std::string_view name;
    size_t size;
    size_t align;
    const void* tag;
};

template <class T>
const TypeInfo& type_info_of() {
    static const TypeInfo info{detail::type_name_of<T>(), detail::size_of_type<T>(),
                               detail::align_of_type<T>(), &detail::TypeTag<T>::id};
    return info;
}

/// Are `a` and `b` the same C++ type? The same object in one binary; across binaries (a
/// module compiled at run time and the program that loaded it) the same name, size and
/// alignment.
inline bool same_type(const TypeInfo& a, const TypeInfo& b) {
    return detail::same_type_tag(a.tag, b.tag);
}

/// What kind of value a record field holds; decides which variable values fit it.
enum class FieldKind {
    kFloat,
    kFloat2,
    kFloat3,
    kFloat4,
    kInt,
    kInt2,
    kInt3,
    kInt4,
    kUint,
    kUint2,
    kUint3,
    kUint4,
    kMatrix4x3,
    kBuffer,    // BufferView<T>: element type in `element`
    kTexture,   // TextureView
    kHandle,    // a graph node
    kCallable,  // Callable<Sig>: signature in `element`
    kUserData,  // any other POD struct: type in `element`
};

const char* field_kind_name(FieldKind kind);

template <class T>
struct FieldKindOf {
    static constexpr FieldKind value = FieldKind::kUserData;
};
#define LUCENT_FIELD_KIND(T, K)                          \
    template <>                                          \
    struct FieldKindOf<T> {                              \
        static constexpr FieldKind value = FieldKind::K; \
    };
LUCENT_FIELD_KIND(float, kFloat)
LUCENT_FIELD_KIND(float2, kFloat2)
LUCENT_FIELD_KIND(float3, kFloat3)
LUCENT_FIELD_KIND(float4, kFloat4)
LUCENT_FIELD_KIND(int, kInt)
LUCENT_FIELD_KIND(int2, kInt2)
LUCENT_FIELD_KIND(int3, kInt3)
LUCENT_FIELD_KIND(int4, kInt4)
LUCENT_FIELD_KIND(unsigned, kUint)
LUCENT_FIELD_KIND(uint2, kUint2)
LUCENT_FIELD_KIND(uint3, kUint3)
LUCENT_FIELD_KIND(uint4, kUint4)
LUCENT_FIELD_KIND(Matrix4x3, kMatrix4x3)
LUCENT_FIELD_KIND(TextureView, kTexture)
LUCENT_FIELD_KIND(Handle, kHandle)
#undef LUCENT_FIELD_KIND
template <class T>
struct FieldKindOf<BufferView<T>> {
    static constexpr FieldKind value = FieldKind::kBuffer;
};
template <class S>
struct FieldKindOf<Callable<S>> {
    static constexpr FieldKind value = FieldKind::kCallable;
};

template <class T>
struct FieldElement {
    using type = T;
};
template <class T>
struct FieldElement<BufferView<T>> {
    using type = std::remove_const_t<T>;  // BufferView<const T> views a buffer of T
};
/// BufferView<const T>: the program only reads the buffer. A multi-device launch then need
/// not gather it from the devices (docs/multi-device.md).
template <class T>
struct FieldReadOnly {
    static constexpr bool value = false;
};
template <class T>
struct FieldReadOnly<BufferView<const T>> {
    static constexpr bool value = true;
};
template <class S>
struct FieldElement<Callable<S>> {
    using type = S;
};

/// One named field of a record.
struct FieldInfo {
    std::string_view name;
    size_t offset;
    size_t size;
    FieldKind kind;
    const TypeInfo* element;  // buffer element, callable signature or user struct; else null
    bool read_only = false;   // BufferView<const T>
};

/// A record type: its name, size and fields, from LUCENT_RECORD.
struct RecordInfo {
    std::string_view name;
    size_t size;
    size_t align;
    std::vector<FieldInfo> fields;
};

template <class Record, class Field>
FieldInfo make_field_info(std::string_view name, size_t offset) {
    using Element = typename FieldElement<Field>::type;
    constexpr FieldKind kind = FieldKindOf<Field>::value;
    const bool has_element =
        kind == FieldKind::kBuffer || kind == FieldKind::kCallable || kind == FieldKind::kUserData;
    return FieldInfo{name, offset, sizeof(Field), kind,
                     has_element ? &type_info_of<Element>() : nullptr, FieldReadOnly<Field>::value};
}

inline const RecordInfo& lucent_record_info(const NoRecord*) {
    static const RecordInfo info{"NoRecord", sizeof(NoRecord), alignof(NoRecord), {}};
    return info;
}

template <class Record>
const RecordInfo& record_info_of() {
    return lucent_record_info(static_cast<const Record*>(nullptr));  // found by ADL
}

}  // namespace lucent

// ---- LUCENT_RECORD(Type, field, field, ...) ----------------------------------
#define LUCENT_PP_CAT_(a, b) a##b
#define LUCENT_PP_CAT(a, b) LUCENT_PP_CAT_(a, b)
#define LUCENT_PP_NARG(...)                                                                        \
    LUCENT_PP_NARG_(__VA_ARGS__, 24, 23, 22, 21, 20, 19, 18, 17, 16, 15, 14, 13, 12, 11, 10, 9, 8, \
                    7, 6, 5, 4, 3, 2, 1, 0)
#define LUCENT_PP_NARG_(_1, _2, _3, _4, _5, _6, _7, _8, _9, _10, _11, _12, _13, _14, _15, _16, \
                        _17, _18, _19, _20, _21, _22, _23, _24, N, ...)                        \
    N
#define LUCENT_FE_1(m, T, x) m(T, x)
#define LUCENT_FE_2(m, T, x, ...) m(T, x) LUCENT_FE_1(m, T, __VA_ARGS__)
#define LUCENT_FE_3(m, T, x, ...) m(T, x) LUCENT_FE_2(m, T, __VA_ARGS__)
#define LUCENT_FE_4(m, T, x, ...) m(T, x) LUCENT_FE_3(m, T, __VA_ARGS__)
#define LUCENT_FE_5(m, T, x, ...) m(T, x) LUCENT_FE_4(m, T, __VA_ARGS__)
#define LUCENT_FE_6(m, T, x, ...) m(T, x) LUCENT_FE_5(m, T, __VA_ARGS__)
#define LUCENT_FE_7(m, T, x, ...) m(T, x) LUCENT_FE_6(m, T, __VA_ARGS__)
#define LUCENT_FE_8(m, T, x, ...) m(T, x) LUCENT_FE_7(m, T, __VA_ARGS__)
#define LUCENT_FE_9(m, T, x, ...) m(T, x) LUCENT_FE_8(m, T, __VA_ARGS__)
#define LUCENT_FE_10(m, T, x, ...) m(T, x) LUCENT_FE_9(m, T, __VA_ARGS__)
#define LUCENT_FE_11(m, T, x, ...) m(T, x) LUCENT_FE_10(m, T, __VA_ARGS__)
#define LUCENT_FE_12(m, T, x, ...) m(T, x) LUCENT_FE_11(m, T, __VA_ARGS__)
#define LUCENT_FE_13(m, T, x, ...) m(T, x) LUCENT_FE_12(m, T, __VA_ARGS__)
#define LUCENT_FE_14(m, T, x, ...) m(T, x) LUCENT_FE_13(m, T, __VA_ARGS__)
#define LUCENT_FE_15(m, T, x, ...) m(T, x) LUCENT_FE_14(m, T, __VA_ARGS__)
#define LUCENT_FE_16(m, T, x, ...) m(T, x) LUCENT_FE_15(m, T, __VA_ARGS__)
#define LUCENT_FE_17(m, T, x, ...) m(T, x) LUCENT_FE_16(m, T, __VA_ARGS__)
#define LUCENT_FE_18(m, T, x, ...) m(T, x) LUCENT_FE_17(m, T, __VA_ARGS__)
#define LUCENT_FE_19(m, T, x, ...) m(T, x) LUCENT_FE_18(m, T, __VA_ARGS__)
#define LUCENT_FE_20(m, T, x, ...) m(T, x) LUCENT_FE_19(m, T, __VA_ARGS__)
#define LUCENT_FE_21(m, T, x, ...) m(T, x) LUCENT_FE_20(m, T, __VA_ARGS__)
#define LUCENT_FE_22(m, T, x, ...) m(T, x) LUCENT_FE_21(m, T, __VA_ARGS__)
#define LUCENT_FE_23(m, T, x, ...) m(T, x) LUCENT_FE_22(m, T, __VA_ARGS__)
#define LUCENT_FE_24(m, T, x, ...) m(T, x) LUCENT_FE_23(m, T, __VA_ARGS__)
#define LUCENT_FOR_EACH(m, T, ...) \
    LUCENT_PP_CAT(LUCENT_FE_, LUCENT_PP_NARG(__VA_ARGS__))(m, T, __VA_ARGS__)
#define LUCENT_RECORD_FIELD_(T, f) ::lucent::make_field_info<T, decltype(T::f)>(#f, offsetof(T, f)),

/// Declare the named fields of a record struct (its program variables), so the host can
/// resolve each one through the variable scopes and pack the record.
#define LUCENT_RECORD(T, ...)                                                                    \
    inline const ::lucent::RecordInfo& lucent_record_info(const T*) {                            \
        static const ::lucent::RecordInfo info{                                                  \
            #T, sizeof(T), alignof(T), {LUCENT_FOR_EACH(LUCENT_RECORD_FIELD_, T, __VA_ARGS__)}}; \
        return info;                                                                             \
    }

#else  // GPU code: reflection is a host concern
#define LUCENT_RECORD(T, ...)
#endif

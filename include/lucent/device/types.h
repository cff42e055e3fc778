// Plain types that programs see: rays, node handles, buffer and texture views,
// boxes, exception codes. All are POD with the same layout on every backend.
#pragma once

#include "lucent/device/vector_math.h"

namespace lucent {

constexpr float kInfinity = 1e30f;  // "no upper bound" for ray intervals

/// A ray: origin, direction (not necessarily unit), ray type, the interval [tmin, tmax] and
/// its time (OptiX's rayTime): where moving geometry and motion transforms are taken. Time
/// 0 by default; scenes without motion ignore it.
struct Ray {
    float3 origin;
    float tmin;
    float3 direction;
    float tmax;
    unsigned ray_type;
    float time;
};

LUCENT_HD inline Ray make_ray(float3 origin, float3 direction, unsigned ray_type, float tmin,
                              float tmax = kInfinity, float time = 0.0f) {
    Ray r;
    r.origin = origin;
    r.direction = direction;
    r.tmin = tmin;
    r.tmax = tmax;
    r.ray_type = ray_type;
    r.time = time;
    return r;
}

/// A node of the compiled scene graph that a program may trace against.
struct Handle {
    unsigned index;
};
constexpr unsigned kInvalidHandle = 0xffffffffu;

/// Axis-aligned box, written by bounding-box programs.
struct Aabb {
    float3 lo;
    float3 hi;
};

/// Affine 4x3 matrix, row-major: rows are (m[0..3]), (m[4..7]), (m[8..11]).
struct Matrix4x3 {
    float m[12];
};

LUCENT_HD inline Matrix4x3 identity_matrix() {
    Matrix4x3 m{};
    m.m[0] = m.m[5] = m.m[10] = 1.0f;
    return m;
}
LUCENT_HD inline float3 transform_point(const Matrix4x3& a, float3 p) {
    return make_float3(a.m[0] * p.x + a.m[1] * p.y + a.m[2] * p.z + a.m[3],
                       a.m[4] * p.x + a.m[5] * p.y + a.m[6] * p.z + a.m[7],
                       a.m[8] * p.x + a.m[9] * p.y + a.m[10] * p.z + a.m[11]);
}
LUCENT_HD inline float3 transform_vector(const Matrix4x3& a, float3 v) {
    return make_float3(a.m[0] * v.x + a.m[1] * v.y + a.m[2] * v.z,
                       a.m[4] * v.x + a.m[5] * v.y + a.m[6] * v.z,
                       a.m[8] * v.x + a.m[9] * v.y + a.m[10] * v.z);
}
/// Normals transform by the inverse transpose: pass the *inverse* matrix here.
LUCENT_HD inline float3 transform_normal_by_inverse(const Matrix4x3& inv, float3 n) {
    return make_float3(inv.m[0] * n.x + inv.m[4] * n.y + inv.m[8] * n.z,
                       inv.m[1] * n.x + inv.m[5] * n.y + inv.m[9] * n.z,
                       inv.m[2] * n.x + inv.m[6] * n.y + inv.m[10] * n.z);
}

/// Flags of a motion range (MotionOptions, OptiX's OptixMotionFlags): outside [time_begin,
/// time_end] an object is held at its first or last key (clamped) unless its flag says it
/// vanishes there.
enum MotionFlags : unsigned {
    kMotionFlagNone = 0,
    kMotionFlagStartVanish = 1u << 0,  // absent for times before time_begin
    kMotionFlagEndVanish = 1u << 1,    // absent for times after time_end
};

/// One key of a scale-rotation-translation motion transform (OptiX's OptixSRTData): the
/// key's object-to-world transform is T * R * S, where S is the upper-triangular
/// scale/shear matrix with the pivot as its translation column,
///     S = [sx a b pvx; 0 sy c pvy; 0 0 sz pvz],
/// R rotates by the unit quaternion (qx, qy, qz, qw) and T translates by (tx, ty, tz).
/// Between keys every component is interpolated linearly, the quaternion by normalised
/// linear interpolation (nlerp), as OptiX does.
struct SrtData {
    float sx, a, b, pvx, sy, c, pvy, sz, pvz, qx, qy, qz, qw, tx, ty, tz;
};

/// Engine exception codes; user codes start at kUserExceptionBase.
enum ExceptionCode : int {
    kExceptionStackOverflow = 1,
    kExceptionBufferIndexOutOfBounds = 2,
    kExceptionPayloadTypeMismatch = 3,
    kExceptionInvalidHandle = 4,
    kExceptionInvalidRayType = 5,
    kExceptionMaterialIndexOutOfRange = 6,
    /// trace() or occluded() with ray flags that contradict each other, flags occluded()
    /// cannot honour, or a visibility mask above 0xff (detail: mask << 16 | flags).
    kExceptionInvalidRayFlags = 7,
    kUserExceptionBase = 0x400,
};

/// Per-ray control of trace() and occluded(): OptiX 7's OptixRayFlags, the same meanings and
/// bits. "Opaque" is a primitive whose any-hit program does not run: its geometry has
/// kGeometryFlagDisableAnyHit (GeometryBase::set_flags), unless the ray's flags override it.
enum RayFlags : unsigned {
    kRayFlagNone = 0,
    /// Every primitive is opaque for this ray: no any-hit program runs.
    kRayFlagDisableAnyHit = 1u << 0,
    /// No primitive is opaque for this ray: any-hit programs run even on opaque geometry.
    kRayFlagEnforceAnyHit = 1u << 1,
    /// The first hit accepted (by any-hit, or opaque) ends traversal; closest hit then runs
    /// on it, which need not be the nearest.
    kRayFlagTerminateOnFirstHit = 1u << 2,
    /// No closest-hit program runs (miss programs still do).
    kRayFlagDisableClosestHit = 1u << 3,
    /// Built-in triangles seen from behind are skipped. A triangle is front-facing when its
    /// vertices appear counter-clockwise from the ray origin, in object space: the ray
    /// direction opposes cross(p1 - p0, p2 - p0).
    kRayFlagCullBackFacingTriangles = 1u << 4,
    /// Built-in triangles seen from the front are skipped.
    kRayFlagCullFrontFacingTriangles = 1u << 5,
    /// Opaque primitives are skipped.
    kRayFlagCullDisabledAnyHit = 1u << 6,
    /// Non-opaque primitives are skipped.
    kRayFlagCullEnforcedAnyHit = 1u << 7,
};
/// Every valid RayFlags bit.
constexpr unsigned kRayFlagsAll = 0xffu;
/// The four flags that choose how any-hit is treated: at most one per ray (as in OptiX).
constexpr unsigned kRayFlagsAnyHitChoice = kRayFlagDisableAnyHit | kRayFlagEnforceAnyHit |
                                           kRayFlagCullDisabledAnyHit | kRayFlagCullEnforcedAnyHit;
/// The two facing culls: at most one per ray.
constexpr unsigned kRayFlagsFacingCull =
    kRayFlagCullBackFacingTriangles | kRayFlagCullFrontFacingTriangles;

/// Visibility masks: 8 bits on rays and on nodes and geometry instances; a ray skips a node
/// or an instance whose mask shares no bit with its own (OptiX's visibilityMask).
constexpr unsigned kVisibilityMaskAll = 0xffu;

/// Flags of a geometry (GeometryBase::set_flags): OptiX's OptixGeometryFlags.
enum GeometryFlags : unsigned {
    kGeometryFlagNone = 0,
    /// The geometry is opaque: its any-hit programs never run (unless a ray has
    /// kRayFlagEnforceAnyHit), and a ray's traversal of it takes the fast closest-hit path.
    kGeometryFlagDisableAnyHit = 1u << 0,
};

/// The largest attribute type an intersection or attribute program may write: the engine's
/// attribute scratch space, on both backends. Checked where a program is declared.
constexpr unsigned kMaxAttributeBytes = 256;

/// What the exception program receives.
struct ExceptionInfo {
    int code;
    uint3 launch_index;
    unsigned detail;  // the out-of-range index, the depth reached, or 0
};

/// Attributes of the built-in triangles when no attribute program is bound:
/// barycentrics (u, v) of vertices 1 and 2, and the object-space geometric normal.
struct TriangleAttributes {
    float2 barycentrics;
    float3 geometric_normal;
};

/// Attributes of built-in spheres (GeometrySpheres): the object-space unit normal at the
/// hit, pointing out of the sphere, and whether the ray entered the sphere there (1) or
/// left it (0: the far side, e.g. of a ray that starts inside).
struct BuiltinSphereAttributes {
    float3 normal;
    unsigned entering;
};

/// GeometryCurves' curve types (OptiX's OPTIX_PRIMITIVE_TYPE_ROUND_*). A segment reads
/// curve_control_points(type) consecutive vertices and radii from its segment index.
enum CurveType : unsigned {
    kCurveLinear = 0,            // 2 points: a cone between two spheres
    kCurveQuadraticBSpline = 1,  // 3 points, uniform quadratic B-spline
    kCurveCubicBSpline = 2,      // 4 points, uniform cubic B-spline
    kCurveCatmullRom = 3,        // 4 points, from the second to the third
};
constexpr unsigned kCurveTypeCount = 4;

LUCENT_HD inline unsigned curve_control_points(unsigned type) {
    return type == kCurveLinear ? 2u : type == kCurveQuadraticBSpline ? 3u : 4u;
}

/// Attributes of built-in curves (GeometryCurves): the object-space unit normal at the hit
/// (from the centre line's sphere through the hit, pointing out of the tube), the segment's
/// parameter u in [0, 1] (OptiX's optixGetCurveParameter), and whether the ray entered the
/// tube there (1) or left it (0).
struct BuiltinCurveAttributes {
    float3 normal;
    float u;
    unsigned entering;
};

/// A record with no variables, for programs that need none.
struct NoRecord {};

/// Per-program flags packed into views by the scene compiler.
enum ViewFlags : unsigned { kViewBoundsChecked = 1u };

/// Typed view of a Buffer (1D, 2D or 3D) as a program sees it.
template <class T>
struct BufferView {
    T* data;
    uint3 size;      // unused dimensions are 1
    unsigned flags;  // kViewBoundsChecked when out-of-bounds exceptions are on

    LUCENT_HD unsigned count() const { return size.x * size.y * size.z; }
    LUCENT_HD T& operator[](unsigned i) const;
    LUCENT_HD T& operator[](uint2 i) const;
    LUCENT_HD T& operator[](uint3 i) const;
    LUCENT_HD T* begin() const { return data; }
    LUCENT_HD T* end() const { return data + count(); }

  private:
    LUCENT_HD T& out_of_bounds(unsigned linear) const;  // raises the exception
};

enum class WrapMode : unsigned { kRepeat = 0, kClampToEdge = 1, kMirror = 2 };
enum class FilterMode : unsigned { kNearest = 0, kLinear = 1 };

/// A 2D float4 texture as a program sees it (the host TextureSampler packs into this).
struct TextureView {
    const float4* texels;
    unsigned width, height;
    WrapMode wrap_u, wrap_v;
    FilterMode filter;
};

/// A callable program bound through a variable: call it like a function.
/// On the CPU it is a function pointer and the program's packed record.
template <class Signature>
struct Callable;
namespace detail {
template <class Signature>
struct CallableTag {};  // selects the generated GPU dispatch of one signature (found by ADL)
#if LUCENT_GPU_CODE
/// Chosen only when the scene binds no callable of this signature (the megakernel then has
/// no dispatch for it): a value-initialised result.
template <class R, class... Args, class... A>
__device__ R lucent_gpu_call(CallableTag<R(Args...)>, unsigned, unsigned, A...) {
    return R();
}
#endif
}  // namespace detail
template <class R, class... Args>
struct Callable<R(Args...)> {
    // CPU: the program's thunk and its record. GPU: the program's dispatch id and its
    // record's offset in the megakernel's record blob.
    R (*fn)(const void* record, Args...);
    const void* record;
    LUCENT_HD R operator()(Args... args) const {
#if LUCENT_GPU_CODE
        return lucent_gpu_call(detail::CallableTag<R(Args...)>{},
                               unsigned(reinterpret_cast<unsigned long long>(fn)),
                               unsigned(reinterpret_cast<unsigned long long>(record)), args...);
#else
        return fn(record, args...);
#endif
    }
};

}  // namespace lucent

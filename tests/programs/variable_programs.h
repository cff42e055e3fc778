// Programs of variables_test: each program kind copies one variable of its record
// (named <kind>_value) to where the host can read it, so the test can see which scope
// the value was resolved from.
#pragma once

#include "tests/programs/common.h"

namespace lucent_tests {
// Each test module in its own inline namespace: its own LUCENT_MODULE, while the tests
// still name its programs and types unqualified.
inline namespace variable_module {
LUCENT_MODULE(test_variable)

struct VtPayload {
    int hit;  // -1 untouched, 0 miss, 1 closest hit
    float ch, ah, is, attr, rg, miss;
};

struct VtAttributes {
    float3 normal;
    float is_value;    // from the intersection program's record
    float attr_value;  // from the attribute program's record
};

// ---- geometry: intersection, bounding box, attribute --------------------------------
struct VtIntersectRecord {
    BufferView<float4> spheres;
    float is_value;
};
LUCENT_RECORD(VtIntersectRecord, spheres, is_value)
LUCENT_INTERSECTION(vt_sphere_intersect, VtIntersectRecord, VtAttributes) {
    attr.is_value = rec.is_value;
    attr.attr_value = -1.0f;
    intersect_sphere(rec.spheres[prim], 0, attr);
}

struct VtBoundsRecord {
    BufferView<float4> spheres;
    float bb_value;
    BufferView<float> bb_log;  // bounding-box programs have no payload: log through a buffer
};
LUCENT_RECORD(VtBoundsRecord, spheres, bb_value, bb_log)
LUCENT_BOUNDING_BOX(vt_sphere_bounds, VtBoundsRecord) {
    rec.bb_log[0] = rec.bb_value;
    const float4 s = rec.spheres[prim];
    box.lo = make_float3(s.x - s.w, s.y - s.w, s.z - s.w);
    box.hi = make_float3(s.x + s.w, s.y + s.w, s.z + s.w);
}

struct VtAttributeRecord {
    float attr_value;
};
LUCENT_RECORD(VtAttributeRecord, attr_value)
LUCENT_ATTRIBUTE(vt_triangle_attributes, VtAttributeRecord, VtAttributes) {
    attr.normal = make_float3(0, 0, 1);
    attr.is_value = -1.0f;
    attr.attr_value = rec.attr_value;
}

// ---- material: closest hit and any hit ----------------------------------------------
struct VtClosestRecord {
    float ch_value;
};
LUCENT_RECORD(VtClosestRecord, ch_value)
LUCENT_CLOSEST_HIT(vt_closest, VtClosestRecord, VtPayload, VtAttributes) {
    prd.hit = 1;
    prd.ch = rec.ch_value;
    prd.is = attr.is_value;
    prd.attr = attr.attr_value;
}

struct VtAnyRecord {
    float ah_value;
};
LUCENT_RECORD(VtAnyRecord, ah_value)
LUCENT_ANY_HIT(vt_any, VtAnyRecord, VtPayload, VtAttributes) {
    prd.ah = rec.ah_value;
}

// ---- miss, ray generation, exception, visit --------------------------------------
struct VtMissRecord {
    float miss_value;
};
LUCENT_RECORD(VtMissRecord, miss_value)
LUCENT_MISS(vt_miss, VtMissRecord, VtPayload) {
    prd.hit = 0;
    prd.miss = rec.miss_value;
}

struct VtCastRecord {
    Handle top;
    float rg_value;
    float3 ray_direction;
    BufferView<VtPayload> out;
};
LUCENT_RECORD(VtCastRecord, top, rg_value, ray_direction, out)
LUCENT_RAY_GENERATION(vt_cast, VtCastRecord) {
    VtPayload p{-1, -1, -1, -1, -1, -1, -1};
    trace(rec.top, make_ray(make_float3(0, 0, 0), rec.ray_direction, 0, 1e-4f), p);
    p.rg = rec.rg_value;
    rec.out[0] = p;
}

LUCENT_RAY_GENERATION(vt_throw, NoRecord) {
    throw_exception(kUserExceptionBase + 1);
}

struct VtExceptionRecord {
    float ex_value;
    BufferView<float> ex_log;
};
LUCENT_RECORD(VtExceptionRecord, ex_value, ex_log)
LUCENT_EXCEPTION(vt_exception, VtExceptionRecord) {
    rec.ex_log[0] = rec.ex_value;
}

struct VtVisitRecord {
    unsigned visit_value;
};
LUCENT_RECORD(VtVisitRecord, visit_value)
LUCENT_VISIT(vt_visit, VtVisitRecord) {
    return rec.visit_value;
}

// ---- a record with a field of every kind ------------------------------------------
struct Light {
    float3 position;
    float intensity;
    unsigned flags;
};

struct AllKindsOut {
    float f;
    float2 f2;
    float3 f3;
    float4 f4;
    int i;
    int2 i2;
    int3 i3;
    int4 i4;
    unsigned u;
    uint2 u2;
    uint3 u3;
    uint4 u4;
    Matrix4x3 m;
    unsigned value_count;
    float value_sum;
    float4 texel;
    int handle_hit;
    float3 called;
    Light light;
};

struct AllKinds {
    float f;
    float2 f2;
    float3 f3;
    float4 f4;
    int i;
    int2 i2;
    int3 i3;
    int4 i4;
    unsigned u;
    uint2 u2;
    uint3 u3;
    uint4 u4;
    Matrix4x3 m;
    BufferView<float> values;
    TextureView tex;
    Handle scene;
    Callable<float3(float3)> fn;
    Light light;
    BufferView<AllKindsOut> all_out;
};
LUCENT_RECORD(AllKinds, f, f2, f3, f4, i, i2, i3, i4, u, u2, u3, u4, m, values, tex, scene, fn,
              light, all_out)

LUCENT_CALLABLE(vt_negate, NoRecord, float3, (float3 v)) {
    return -v;
}

struct VtScaleRecord {
    float scale;
};
LUCENT_RECORD(VtScaleRecord, scale)
LUCENT_CALLABLE(vt_scale, VtScaleRecord, float3, (float3 v)) {
    return v * rec.scale;
}

LUCENT_RAY_GENERATION(vt_all_kinds, AllKinds) {
    AllKindsOut o;
    o.f = rec.f;
    o.f2 = rec.f2;
    o.f3 = rec.f3;
    o.f4 = rec.f4;
    o.i = rec.i;
    o.i2 = rec.i2;
    o.i3 = rec.i3;
    o.i4 = rec.i4;
    o.u = rec.u;
    o.u2 = rec.u2;
    o.u3 = rec.u3;
    o.u4 = rec.u4;
    o.m = rec.m;
    o.value_count = rec.values.count();
    o.value_sum = 0;
    for (float v : rec.values) o.value_sum += v;
    o.texel = tex2D(rec.tex, make_float2(0.5f, 0.5f));
    VtPayload p{-1, -1, -1, -1, -1, -1, -1};
    trace(rec.scene, make_ray(make_float3(0, 0, 0), make_float3(0, 0, 1), 0, 1e-4f), p);
    o.handle_hit = p.hit;
    o.called = rec.fn(make_float3(1, 2, 3));
    o.light = rec.light;
    rec.all_out[0] = o;
}

}  // namespace variable_module
}  // namespace lucent_tests

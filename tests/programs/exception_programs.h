// Programs of exceptions_test: unbounded recursion, out-of-bounds reads, user exceptions,
// and an exception program that records what it receives.
#pragma once

#include "tests/programs/common.h"

namespace lucent_tests {
// Each test module in its own inline namespace: its own LUCENT_MODULE, while the tests
// still name its programs and types unqualified.
inline namespace exception_module {
LUCENT_MODULE(test_exception)

// ---- recursion to a chosen depth ------------------------------------------------------
struct DepthRecord {
    Handle top;
    int wanted_depth;  // traces nest this deep (ray generation's trace is depth 1)
};
LUCENT_RECORD(DepthRecord, top, wanted_depth)
LUCENT_CLOSEST_HIT(et_recurse, DepthRecord, TestPayload, TriangleAttributes) {
    prd.hit = 1;
    if (prd.depth >= rec.wanted_depth) return;
    TestPayload child = make_test_payload();
    child.depth = prd.depth + 1;
    // The same ray again (full interval): it hits the same surface, one level deeper.
    const Ray& ray = current_ray();
    trace(rec.top, make_ray(ray.origin, ray.direction, 0, ray.tmin), child);
    prd.depth = child.depth;
}

struct DepthGenRecord {
    Handle top;
    BufferView<int> depths;
};
LUCENT_RECORD(DepthGenRecord, top, depths)
LUCENT_RAY_GENERATION(et_trace_depth, DepthGenRecord) {
    TestPayload p = make_test_payload();
    trace(rec.top, make_ray(make_float3(0.3f, 0.1f, 0), make_float3(0, 0, 1), 0, 1e-4f), p);
    rec.depths[launch_index().x] = p.depth;
}

// ---- buffer reads ----------------------------------------------------------------------
struct ReadRecord {
    BufferView<float> input;
    BufferView<float> output;
};
LUCENT_RECORD(ReadRecord, input, output)
/// output[i] = 2 * input[i]; out of bounds where the input is shorter than the launch.
LUCENT_RAY_GENERATION(et_read_1d, ReadRecord) {
    const unsigned i = launch_index().x;
    rec.output[i] = 2.0f * rec.input[i];
}

struct Read2DRecord {
    BufferView<float> input2d;
    BufferView<float> output2d;
};
LUCENT_RECORD(Read2DRecord, input2d, output2d)
LUCENT_RAY_GENERATION(et_read_2d, Read2DRecord) {
    const uint2 i = make_uint2(launch_index().x, launch_index().y);
    rec.output2d[i] = 2.0f * rec.input2d[i];
}

struct WriteRecord {
    BufferView<float> output;
};
LUCENT_RECORD(WriteRecord, output)
/// Writes one past the end at the last launch index (only launched with checks on).
LUCENT_RAY_GENERATION(et_write_past_end, WriteRecord) {
    const unsigned i = launch_index().x;
    rec.output[i + (i + 1 == launch_size().x ? 1u : 0u)] = 1.0f;
}

// ---- user exceptions -----------------------------------------------------------------
struct ThrowRecord {
    BufferView<unsigned> done;  // 1 where the program ran to its end
};
LUCENT_RECORD(ThrowRecord, done)
constexpr int kCodeA = kUserExceptionBase + 7;
constexpr int kCodeB = kUserExceptionBase + 8;
/// On a 4x3 launch: (2,1) and (1,2) raise code A, (3,0) raises code B; detail = 100x + y.
LUCENT_RAY_GENERATION(et_throw_some, ThrowRecord) {
    const uint3 i = launch_index();
    const unsigned detail = 100u * i.x + i.y;
    if ((i.x == 2 && i.y == 1) || (i.x == 1 && i.y == 2)) throw_exception(kCodeA, detail);
    if (i.x == 3 && i.y == 0) throw_exception(kCodeB, detail);
    rec.done[make_uint2(i.x, i.y)] = 1u;
}

// ---- the exception program ----------------------------------------------------------
struct ExceptionLogRecord {
    BufferView<ExceptionInfo> infos;  // one per launch index, linearised
};
LUCENT_RECORD(ExceptionLogRecord, infos)
LUCENT_EXCEPTION(et_log_exception, ExceptionLogRecord) {
    const uint3 s = launch_size();
    const uint3 i = ex.launch_index;
    rec.infos[(i.z * s.y + i.y) * s.x + i.x] = ex;
}

// ---- exceptions raised below the ray generation program --------------------------------
/// Closest hit that raises code A (detail 99) on odd launch indices.
LUCENT_CLOSEST_HIT(et_throw_in_hit, NoRecord, TestPayload, TriangleAttributes) {
    prd.hit = 1;
    if (launch_index().x % 2 == 1) throw_exception(kCodeA, 99);
}

struct WrongPayload {
    float value;
};

struct BadTraceRecord {
    Handle top;
    int mode;  // 0: wrong payload type, 1: invalid handle, 2: undeclared ray type
};
LUCENT_RECORD(BadTraceRecord, top, mode)
LUCENT_RAY_GENERATION(et_bad_trace, BadTraceRecord) {
    const Ray ray = make_ray(make_float3(0.3f, 0.1f, 0), make_float3(0, 0, 1), 0, 1e-4f);
    if (rec.mode == 0) {
        WrongPayload other{0};
        trace(rec.top, ray, other);
    } else if (rec.mode == 1) {
        TestPayload p = make_test_payload();
        trace(Handle{123456u}, ray, p);
    } else {
        TestPayload p = make_test_payload();
        Ray bad = ray;
        bad.ray_type = 9;
        trace(rec.top, bad, p);
    }
}

/// Sphere intersection reporting material 3 on an instance that has one material.
LUCENT_INTERSECTION(et_sphere_bad_material, SphereRecord, SphereAttributes) {
    intersect_sphere(rec.spheres[prim], 3, attr);
}

/// Code A wherever (7x + 13y) % 101 == 5: scattered over every tile of a wide launch.
LUCENT_RAY_GENERATION(et_throw_pattern, NoRecord) {
    const uint3 i = launch_index();
    if ((7u * i.x + 13u * i.y) % 101u == 5u) throw_exception(kCodeA, i.x);
}

}  // namespace exception_module
}  // namespace lucent_tests

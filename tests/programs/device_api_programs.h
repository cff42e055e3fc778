// Programs of device_api_test: each program kind records what the device API answers in it
// (a Probe), and any-hit programs write after ignore_intersection()/terminate_ray() to show
// that those end the program.
#pragma once

#include "tests/programs/common.h"

namespace lucent_tests {
inline namespace device_api_module {
LUCENT_MODULE(test_device_api)

/// What one program saw. Written at probes[launch index * kProbeSlots + slot].
struct Probe {
    unsigned ran;
    float3 ray_origin;  // current_ray()
    float3 ray_direction;
    float ray_tmax;
    float t;               // t_hit()
    unsigned prim;         // primitive_index()
    unsigned potential;    // potential_intersection(t) (the intersection program's own t)
    unsigned reported;     // report_intersection(0)
    float3 world_of_zero;  // object_to_world_point(0, 0, 0)
};
enum ProbeSlot : unsigned {
    kProbeRayGeneration,
    kProbeException,
    kProbeMiss,
    kProbeClosestHit,
    kProbeAnyHit,
    kProbeIntersection,
    kProbeVisit,
    kProbeAttribute,
    kProbeSlots,
};
/// A t inside every probe ray's interval: potential_intersection(kInsideT) is true in an
/// intersection program only.
constexpr float kInsideT = 5.0f;

struct ProbeRecord {
    BufferView<Probe> probes;
};
LUCENT_RECORD(ProbeRecord, probes)

/// The probe of a program that may not open or report a candidate.
LUCENT_HD inline Probe look_around() {
    Probe p{};
    p.ran = 1;
    const Ray& r = current_ray();
    p.ray_origin = r.origin;
    p.ray_direction = r.direction;
    p.ray_tmax = r.tmax;
    p.t = t_hit();
    p.prim = primitive_index();
    p.world_of_zero = object_to_world_point(make_float3(0, 0, 0));
    p.potential = potential_intersection(kInsideT) ? 1u : 0u;
    p.reported = report_intersection(0) ? 1u : 0u;
    return p;
}
LUCENT_HD inline void store_probe(const ProbeRecord& rec, unsigned slot, const Probe& p) {
    rec.probes[launch_index().x * kProbeSlots + slot] = p;
}

struct ProbePayload {
    int hit;  // 0 miss, 1 closest hit
};
/// What the probes' attribute program makes of a triangle hit.
struct ProbeTriangleAttributes {
    float3 normal;
};

struct ProbeCasterRecord {
    Handle top;
    BufferView<CastRay> rays;
    BufferView<Probe> probes;
    unsigned throw_at;  // this launch index raises a user exception after its trace
};
LUCENT_RECORD(ProbeCasterRecord, top, rays, probes, throw_at)
LUCENT_RAY_GENERATION(da_probe_cast, ProbeCasterRecord) {
    const unsigned i = launch_index().x;
    rec.probes[i * kProbeSlots + kProbeRayGeneration] = look_around();
    const CastRay r = rec.rays[i];
    ProbePayload p{-1};
    trace(rec.top, make_ray(r.origin, r.direction, 0, 0.0f, 100.0f), p);
    if (i == rec.throw_at) throw_exception(kUserExceptionBase);
}
LUCENT_EXCEPTION(da_probe_exception, ProbeRecord) {
    store_probe(rec, kProbeException, look_around());
}
LUCENT_MISS(da_probe_miss, ProbeRecord, ProbePayload) {
    prd.hit = 0;
    store_probe(rec, kProbeMiss, look_around());
}
LUCENT_CLOSEST_HIT(da_probe_sphere_hit, ProbeRecord, ProbePayload, SphereAttributes) {
    prd.hit = 1;
    store_probe(rec, kProbeClosestHit, look_around());
}
LUCENT_CLOSEST_HIT(da_probe_triangle_hit, ProbeRecord, ProbePayload, ProbeTriangleAttributes) {
    prd.hit = 1;
    store_probe(rec, kProbeClosestHit, look_around());
}
LUCENT_ANY_HIT(da_probe_any_hit, ProbeRecord, ProbePayload, SphereAttributes) {
    store_probe(rec, kProbeAnyHit, look_around());
}
LUCENT_VISIT(da_probe_visit, ProbeRecord) {
    store_probe(rec, kProbeVisit, look_around());
    return 0;
}

struct ProbeSphereRecord {
    BufferView<float4> spheres;
    BufferView<Probe> probes;
};
LUCENT_RECORD(ProbeSphereRecord, spheres, probes)
/// The unit sphere's entry point: what it sees, then whether its candidate opened and
/// was committed.
LUCENT_INTERSECTION(da_probe_sphere_intersect, ProbeSphereRecord, SphereAttributes) {
    Probe p{};
    p.ran = 1;
    const Ray& r = current_ray();
    p.ray_origin = r.origin;
    p.ray_direction = r.direction;
    p.ray_tmax = r.tmax;
    p.t = t_hit();
    p.prim = primitive_index();
    p.world_of_zero = object_to_world_point(make_float3(0, 0, 0));
    const float4 s = rec.spheres[prim];
    const float3 o = r.origin - make_float3(s.x, s.y, s.z);
    const float b = dot(o, r.direction), a = dot(r.direction, r.direction);
    const float disc = b * b - a * (dot(o, o) - s.w * s.w);
    if (disc >= 0.0f) {
        const float t0 = (-b - sqrtf(disc)) / a;
        p.potential = potential_intersection(t0) ? 1u : 0u;
        if (p.potential) {
            attr.normal = (o + t0 * r.direction) / s.w;
            p.reported = report_intersection(0) ? 1u : 0u;
        }
    }
    rec.probes[launch_index().x * kProbeSlots + kProbeIntersection] = p;
}

LUCENT_ATTRIBUTE(da_probe_attribute, ProbeRecord, ProbeTriangleAttributes) {
    attr.normal = make_float3(0, 0, -1);
    store_probe(rec, kProbeAttribute, look_around());
}

// ---- the interval rules of potential_intersection --------------------------------------
struct IntervalRecord {
    BufferView<float> ts;
    BufferView<unsigned> before;  // potential_intersection(ts[i]) before the commit
    BufferView<unsigned> after;   // ... after report_intersection at commit_t
    BufferView<unsigned> stale;   // [0]: report after a false potential; [1]: a second report
    float commit_t;
};
LUCENT_RECORD(IntervalRecord, ts, before, after, stale, commit_t)
LUCENT_INTERSECTION(da_interval_intersect, IntervalRecord, SphereAttributes) {
    for (unsigned i = 0; i < rec.ts.count(); ++i)
        rec.before[i] = potential_intersection(rec.ts[i]) ? 1u : 0u;
    potential_intersection(-1.0f);
    rec.stale[0] = report_intersection(0) ? 1u : 0u;
    attr.normal = make_float3(0, 0, -1);
    if (potential_intersection(rec.commit_t)) report_intersection(0);
    rec.stale[1] = report_intersection(0) ? 1u : 0u;
    for (unsigned i = 0; i < rec.ts.count(); ++i)
        rec.after[i] = potential_intersection(rec.ts[i]) ? 1u : 0u;
}

// ---- any-hit programs end at ignore_intersection() and terminate_ray() ----------------------
struct EndPayload {
    int hit;           // 0 miss, 1 closest hit
    unsigned calls;    // any-hit invocations
    unsigned after;    // statements run after the end call (must stay 0)
    unsigned reached;  // statements run when the condition did not end the program
    float hit_t;       // t_hit() in the closest hit
};
struct EndCasterRecord {
    Handle top;
    BufferView<CastRay> rays;
    BufferView<EndPayload> results;
};
LUCENT_RECORD(EndCasterRecord, top, rays, results)
LUCENT_RAY_GENERATION(da_end_cast, EndCasterRecord) {
    const unsigned i = launch_index().x;
    const CastRay r = rec.rays[i];
    EndPayload p{-1, 0, 0, 0, -1.0f};
    trace(rec.top, make_ray(r.origin, r.direction, 0, 1e-4f), p);
    rec.results[i] = p;
}
LUCENT_MISS(da_end_miss, NoRecord, EndPayload) {
    prd.hit = 0;
}
LUCENT_CLOSEST_HIT(da_end_hit, NoRecord, EndPayload, TriangleAttributes) {
    prd.hit = 1;
    prd.hit_t = t_hit();
}
LUCENT_ANY_HIT(da_ignore_then_write, NoRecord, EndPayload, TriangleAttributes) {
    ++prd.calls;
    ignore_intersection();
    ++prd.after;
}
LUCENT_ANY_HIT(da_terminate_then_write, NoRecord, EndPayload, TriangleAttributes) {
    ++prd.calls;
    terminate_ray();
    ++prd.after;
}
struct NearRecord {
    float ignore_before;
};
LUCENT_RECORD(NearRecord, ignore_before)
/// Ignores the candidates nearer than `ignore_before`, and counts the others.
LUCENT_ANY_HIT(da_ignore_near, NearRecord, EndPayload, TriangleAttributes) {
    ++prd.calls;
    if (t_hit() < rec.ignore_before) ignore_intersection();
    ++prd.reached;
}
/// Terminates at the first candidate beyond `ignore_before`; ignores the nearer ones.
LUCENT_ANY_HIT(da_terminate_far, NearRecord, EndPayload, TriangleAttributes) {
    ++prd.calls;
    if (t_hit() < rec.ignore_before)
        ignore_intersection();
    else
        terminate_ray();
    ++prd.after;
}

// ---- exceptions ---------------------------------------------------------------------------
struct BadPayload {
    double wrong;  // neither the size nor the alignment of ProbePayload
    double more;
};
struct BadTraceRecord {
    Handle top;
    unsigned mode;  // 0 ray type, 1 payload, 2 handle, 3 depth, 4 material index
    BufferView<int> finished;
};
LUCENT_RECORD(BadTraceRecord, top, mode, finished)
LUCENT_RAY_GENERATION(da_bad_trace, BadTraceRecord) {
    const Ray ray = make_ray(make_float3(0, 0, -5), make_float3(0, 0, 1), 0, 0.0f, 100.0f);
    if (rec.mode == 1) {
        BadPayload p{};
        trace(rec.top, ray, p);
    } else {
        ProbePayload p{-1};
        Ray r = ray;
        if (rec.mode == 0) r.ray_type = 9;
        trace(rec.mode == 2 ? Handle{9999} : rec.top, r, p);
    }
    rec.finished[launch_index().x] = 1;
}
LUCENT_MISS(da_bad_trace_miss, NoRecord, ProbePayload) {
    prd.hit = 0;
}
/// Traces again from its hit: with a maximum depth of 1 the second trace overflows.
LUCENT_CLOSEST_HIT(da_retrace, BadTraceRecord, ProbePayload, SphereAttributes) {
    prd.hit = 1;
    ProbePayload inner{-1};
    trace(rec.top, make_ray(make_float3(0, 0, -5), make_float3(0, 0, 1), 0, 0.0f, 100.0f), inner);
}
LUCENT_INTERSECTION(da_sphere_material_3, SphereRecord, SphereAttributes) {
    intersect_sphere(rec.spheres[prim], 3, attr);
}
struct ExceptionLogRecord {
    BufferView<ExceptionInfo> infos;
};
LUCENT_RECORD(ExceptionLogRecord, infos)
LUCENT_EXCEPTION(da_log_exception, ExceptionLogRecord) {
    rec.infos[launch_index().x] = ex;
}

}  // namespace device_api_module
}  // namespace lucent_tests

// Programs of the ray-control tests (ray flags, visibility masks, instance ids, opaque
// geometry): a ray generation that traces, or asks occluded() for, each listed ray with its
// own flags and mask, and hit programs that record what they saw.
#pragma once

#include "tests/programs/common.h"

namespace lucent_tests {
inline namespace ray_control_module {
LUCENT_MODULE(test_ray_control, lucent::kUsesOccluded, lucent::kUsesRayFlags)

struct ControlRay {
    float3 origin, direction;
    unsigned flags;      // RayFlags
    unsigned mask;       // visibility mask
    unsigned occlusion;  // 0: trace(); 1: occluded(); 2: occluded(..., kLeafBoxes)
};

struct ControlPayload {
    int hit;  // -1: neither miss nor closest hit ran, 0: miss, 1: closest hit
    unsigned id;                    // the closest hit's `id` variable
    float t;                        // t_hit() in the closest hit
    unsigned anyhit_count;          // any-hit invocations
    unsigned instance_id;           // instance_id() in the closest hit
    unsigned geometry_instance_id;  // geometry_instance_id() in the closest hit
    unsigned anyhit_instance_id;    // instance_id() in the last any-hit
    unsigned anyhit_geometry_id;    // geometry_instance_id() in the last any-hit
    Matrix4x3 to_object;            // world_to_object_matrix() in the closest hit
    Matrix4x3 to_world;             // object_to_world_matrix() in the closest hit
    unsigned occluded;              // occluded()'s answer (occlusion queries)
};

struct ControlRecord {
    Handle top;
    BufferView<ControlRay> rays;
    BufferView<ControlPayload> results;
};
LUCENT_RECORD(ControlRecord, top, rays, results)

LUCENT_RAY_GENERATION(control_cast, ControlRecord) {
    const unsigned i = launch_index().x;
    const ControlRay r = rec.rays[i];
    ControlPayload p{};
    p.hit = -1;
    const Ray ray = make_ray(r.origin, r.direction, 0, 1e-4f);
    if (r.occlusion) {
        const Occlusion test = r.occlusion == 2 ? Occlusion::kLeafBoxes : Occlusion::kExact;
        p.occluded = occluded(rec.top, ray, test, r.flags, r.mask) ? 1u : 0u;
    } else {
        trace(rec.top, ray, p, r.flags, r.mask);
    }
    rec.results[i] = p;
}

LUCENT_MISS(control_miss, NoRecord, ControlPayload) {
    prd.hit = 0;
}

LUCENT_HD inline void record_control_hit(const IdRecord& rec, ControlPayload& prd) {
    prd.hit = 1;
    prd.id = rec.id;
    prd.t = t_hit();
    prd.instance_id = instance_id();
    prd.geometry_instance_id = geometry_instance_id();
    prd.to_object = world_to_object_matrix();
    prd.to_world = object_to_world_matrix();
}

LUCENT_CLOSEST_HIT(control_triangle_hit, IdRecord, ControlPayload, TriangleAttributes) {
    record_control_hit(rec, prd);
}
LUCENT_CLOSEST_HIT(control_sphere_hit, IdRecord, ControlPayload, SphereAttributes) {
    record_control_hit(rec, prd);
}

LUCENT_ANY_HIT(control_count_triangle, NoRecord, ControlPayload, TriangleAttributes) {
    ++prd.anyhit_count;
    prd.anyhit_instance_id = instance_id();
    prd.anyhit_geometry_id = geometry_instance_id();
}
LUCENT_ANY_HIT(control_count_sphere, NoRecord, ControlPayload, SphereAttributes) {
    ++prd.anyhit_count;
    prd.anyhit_instance_id = instance_id();
    prd.anyhit_geometry_id = geometry_instance_id();
}

}  // namespace ray_control_module
}  // namespace lucent_tests

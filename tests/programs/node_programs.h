// Programs of nodes_test: selector visit programs and a second ray type (shadow) traced
// against its own root.
#pragma once

#include "tests/programs/common.h"

namespace lucent_tests {
// Each test module in its own inline namespace: its own LUCENT_MODULE, while the tests
// still name its programs and types unqualified.
inline namespace node_module {
LUCENT_MODULE(test_node)

// ---- selector visit programs --------------------------------------------------------
/// Child 0 for rays going towards +x (or straight), child 1 for rays going towards -x.
LUCENT_VISIT(nt_visit_by_direction, NoRecord) {
    return current_ray().direction.x >= 0.0f ? 0u : 1u;
}

struct ChoiceRecord {
    unsigned choice;
};
LUCENT_RECORD(ChoiceRecord, choice)
LUCENT_VISIT(nt_visit_by_choice, ChoiceRecord) {
    return rec.choice;
}

LUCENT_VISIT(nt_visit_by_launch_index, NoRecord) {
    return launch_index().x % 2u;
}

// ---- a second ray type with its own payload and root ---------------------------------
struct ShadowPayload {
    int hit;  // -1 untouched, 0 miss, 1 closest hit
    float t;
    unsigned id;
};

LUCENT_MISS(nt_shadow_miss, NoRecord, ShadowPayload) {
    prd.hit = 0;
}

LUCENT_CLOSEST_HIT(nt_shadow_hit, IdRecord, ShadowPayload, SphereAttributes) {
    prd.hit = 1;
    prd.t = t_hit();
    prd.id = rec.id;
}

struct TwoRootsRecord {
    Handle radiance_root;
    Handle shadow_root;
    BufferView<CastRay> rays;
    BufferView<TestPayload> radiance;
    BufferView<ShadowPayload> shadow;
};
LUCENT_RECORD(TwoRootsRecord, radiance_root, shadow_root, rays, radiance, shadow)

/// Traces the same ray twice: as ray type 0 against one root, as type 1 against another.
LUCENT_RAY_GENERATION(nt_two_roots, TwoRootsRecord) {
    const unsigned i = launch_index().x;
    const CastRay r = rec.rays[i];
    TestPayload p = make_test_payload();
    trace(rec.radiance_root, make_ray(r.origin, r.direction, 0, 1e-4f), p);
    ShadowPayload s{-1, -1.0f, 0xffffffffu};
    trace(rec.shadow_root, make_ray(r.origin, r.direction, 1, 1e-4f), s);
    rec.radiance[i] = p;
    rec.shadow[i] = s;
}

// ---- programs that look at the transforms of the current position --------------------
/// What an attribute program sees below a Transform: the world-space normal it computes,
/// primitive_index() and the ray it is given.
struct SpaceAttributes {
    float3 world_normal;  // object_to_world_normal of the object-space geometric normal
    float3 ray_origin;    // current_ray().origin inside the attribute program
    unsigned api_prim;    // primitive_index() inside the attribute program
    unsigned prim;        // the prim argument
};
LUCENT_ATTRIBUTE(nt_space_attributes, NoRecord, SpaceAttributes) {
    attr.world_normal = normalize(object_to_world_normal(make_float3(0, 0, 1)));
    attr.ray_origin = current_ray().origin;
    attr.api_prim = primitive_index();
    attr.prim = prim;
}
LUCENT_CLOSEST_HIT(nt_space_hit, IdRecord, TestPayload, SpaceAttributes) {
    prd.hit = 1;
    prd.id = rec.id;
    prd.t = t_hit();
    prd.prim = attr.api_prim;
    prd.normal = attr.world_normal;
    prd.object_point = attr.ray_origin;
    prd.anyhit_count = attr.prim;
}

/// Any hit below a Transform: records t_hit() and the (object-space) ray it sees.
LUCENT_ANY_HIT(nt_anyhit_record, NoRecord, TestPayload, SphereAttributes) {
    prd.anyhit_count += 1;
    prd.anyhit_t = t_hit();
    prd.uv = make_float2(current_ray().origin.z, current_ray().direction.z);
}

}  // namespace node_module
}  // namespace lucent_tests

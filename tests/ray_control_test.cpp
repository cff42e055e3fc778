// Per-ray control as OptiX 7-9 has it: ray flags on trace() and occluded(), opaque geometry,
// visibility masks on nodes and geometry instances, and instance ids with the hit's
// transform matrices. Each case runs on the backend the suite runs on (LUCENT_TEST_BACKEND),
// so the CPU and the GPU are held to the same answers.
#include "tests/programs/ray_control_programs.h"
#include "tests/test_support.h"

namespace {

using namespace lucent;
using namespace lucent_tests;

const float3 kOrigin = make_float3(0, 0, 0), kForward = make_float3(0, 0, 1);
const float3 kFarSide = make_float3(0, 0, 20), kBackward = make_float3(0, 0, -1);

class RayControlTest : public testing::Test {
  protected:
    RayControlTest() : ctx(test_context_options()) {
        ctx.set_entry_point_count(1);
        ctx.set_ray_type<ControlPayload>(0, "radiance");
        ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(control_miss)));
        ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(control_cast)));
    }

    std::vector<ControlPayload> cast(std::shared_ptr<Node> top, const std::vector<ControlRay>& rays,
                                     bool expect_clean = true) {
        auto results = ctx.create_buffer<ControlPayload>(BufferType::kOutput, unsigned(rays.size()));
        auto gen = ctx.ray_generation_program(0);
        (*gen)["top"] = top;
        (*gen)["rays"] = input_buffer(ctx, rays);
        (*gen)["results"] = results;
        ctx.launch(0, unsigned(rays.size()));
        if (expect_clean) {
            EXPECT_EQ(ctx.last_launch().exception_count(), 0u) << ctx.last_launch().summary();
        }
        return read_buffer<ControlPayload>(*results);
    }

    /// A material whose closest hit records `id`, with a counting any-hit when asked.
    std::shared_ptr<Material> triangle_material(unsigned id, bool any_hit = false) {
        auto m = make_material(ctx, program(ctx, LUCENT_PROGRAM(control_triangle_hit)), id);
        if (any_hit) m->set_any_hit(0, program(ctx, LUCENT_PROGRAM(control_count_triangle)));
        return m;
    }
    std::shared_ptr<GeometryInstance> square(float z, unsigned id, bool any_hit = false) {
        return make_instance(ctx, make_triangles(ctx, square_at(z)), triangle_material(id, any_hit));
    }
    std::shared_ptr<GeometryInstance> sphere(float z, unsigned id, bool any_hit = false) {
        auto m = make_material(ctx, program(ctx, LUCENT_PROGRAM(control_sphere_hit)), id);
        if (any_hit) m->set_any_hit(0, program(ctx, LUCENT_PROGRAM(control_count_sphere)));
        return make_instance(ctx, make_spheres(ctx, {make_float4(0, 0, z, 1)}), m);
    }

    static ControlRay ray(float3 origin, float3 direction, unsigned flags = kRayFlagNone,
                          unsigned mask = kVisibilityMaskAll, unsigned occlusion = 0) {
        return ControlRay{origin, direction, flags, mask, occlusion};
    }
    static std::vector<int> hits(const std::vector<ControlPayload>& r) {
        std::vector<int> out;
        for (const auto& p : r) out.push_back(p.hit);
        return out;
    }
    static std::vector<unsigned> ids(const std::vector<ControlPayload>& r) {
        std::vector<unsigned> out;
        for (const auto& p : r) out.push_back(p.hit == 1 ? p.id : 0u);
        return out;
    }
    static std::vector<unsigned> occluded(const std::vector<ControlPayload>& r) {
        std::vector<unsigned> out;
        for (const auto& p : r) out.push_back(p.occluded);
        return out;
    }

    Context ctx;
};

// square_at's triangles wind counter-clockwise seen from +z: cross(p1 - p0, p2 - p0) is +z.
// A ray from the origin along +z sees their backs; one from z = 20 along -z their fronts.
TEST_F(RayControlTest, FacingCullsSkipTrianglesByWindingInObjectSpace) {
    auto top = make_geometry_group(ctx, {square(5.0f, 1)});
    const auto r = cast(top, {ray(kOrigin, kForward),
                              ray(kOrigin, kForward, kRayFlagCullBackFacingTriangles),
                              ray(kOrigin, kForward, kRayFlagCullFrontFacingTriangles),
                              ray(kFarSide, kBackward, kRayFlagCullBackFacingTriangles),
                              ray(kFarSide, kBackward, kRayFlagCullFrontFacingTriangles),
                              ray(kOrigin, kForward, kRayFlagCullBackFacingTriangles,
                                  kVisibilityMaskAll, 1),
                              ray(kFarSide, kBackward, kRayFlagCullBackFacingTriangles,
                                  kVisibilityMaskAll, 1)});
    EXPECT_EQ(hits(r), (std::vector<int>{1, 0, 1, 1, 0, -1, -1}));  // occluded() runs no hit program
    EXPECT_EQ(occluded(r), (std::vector<unsigned>{0, 0, 0, 0, 0, 0, 1}));

    // Mirrored by a Transform (z -> -z), the square lies at z = -5 and a ray along -z from
    // the origin meets its back in object space, where OptiX tests the winding too.
    auto mirror = ctx.create_transform();
    mirror->set_matrix(scaling(1, 1, -1));
    mirror->set_child(top);
    auto group = ctx.create_group();
    group->add_child(mirror);
    const auto m = cast(group, {ray(kOrigin, kBackward, kRayFlagCullBackFacingTriangles),
                                ray(kOrigin, kBackward, kRayFlagCullFrontFacingTriangles)});
    EXPECT_EQ(hits(m), (std::vector<int>{0, 1}));
}

TEST_F(RayControlTest, OpaqueGeometryRunsNoAnyHitUnlessTheRayEnforcesIt) {
    auto opaque = square(5.0f, 1, /*any_hit=*/true);
    opaque->geometry()->set_flags(kGeometryFlagDisableAnyHit);
    auto top = make_geometry_group(ctx, {opaque});
    const auto r = cast(top, {ray(kOrigin, kForward), ray(kOrigin, kForward, kRayFlagEnforceAnyHit),
                              ray(kOrigin, kForward, kRayFlagCullDisabledAnyHit),
                              ray(kOrigin, kForward, kRayFlagCullEnforcedAnyHit)});
    EXPECT_EQ(hits(r), (std::vector<int>{1, 1, 0, 1}));
    EXPECT_EQ(r[0].anyhit_count, 0u) << "opaque geometry ran its any-hit";
    EXPECT_GE(r[1].anyhit_count, 1u) << "kRayFlagEnforceAnyHit did not run the any-hit";
    EXPECT_EQ(r[3].anyhit_count, 0u);
}

TEST_F(RayControlTest, AnyHitFlagsOnNonOpaqueTrianglesAndCustomPrimitives) {
    for (const bool spheres : {false, true}) {
        auto top = make_geometry_group(
            ctx, {spheres ? sphere(5.0f, 2, /*any_hit=*/true) : square(5.0f, 1, true)});
        const auto r = cast(top, {ray(kOrigin, kForward),
                                  ray(kOrigin, kForward, kRayFlagDisableAnyHit),
                                  ray(kOrigin, kForward, kRayFlagCullEnforcedAnyHit),
                                  ray(kOrigin, kForward, kRayFlagCullDisabledAnyHit),
                                  ray(kOrigin, kForward, kRayFlagDisableAnyHit |
                                                             kRayFlagTerminateOnFirstHit)});
        EXPECT_EQ(hits(r), (std::vector<int>{1, 1, 0, 1, 1})) << "spheres " << spheres;
        EXPECT_GE(r[0].anyhit_count, 1u);
        EXPECT_EQ(r[1].anyhit_count, 0u) << "kRayFlagDisableAnyHit ran the any-hit";
        EXPECT_GE(r[3].anyhit_count, 1u);
        EXPECT_EQ(r[4].anyhit_count, 0u);
    }
}

TEST_F(RayControlTest, TerminateOnFirstHitAcceptsOneCandidate) {
    // Squares at 5, 6 and 7 with a counting any-hit: without the flag, the nearest wins;
    // with it, the first accepted candidate ends traversal (any of them, as in OptiX).
    auto top = make_geometry_group(ctx, {square(5.0f, 1, true), square(6.0f, 2, true),
                                         square(7.0f, 3, true)});
    // From the far side, along -z: a traversal that meets the far squares first stops there.
    const auto r = cast(top, {ray(kOrigin, kForward),
                              ray(kOrigin, kForward, kRayFlagTerminateOnFirstHit),
                              ray(kFarSide, kBackward, kRayFlagTerminateOnFirstHit)});
    EXPECT_EQ(ids(r), (std::vector<unsigned>{1, r[1].id, r[2].id}));
    for (int i : {1, 2}) {
        EXPECT_EQ(r[i].hit, 1);
        EXPECT_EQ(r[i].anyhit_count, 1u) << "ray " << i << " accepted more than one candidate";
        EXPECT_FLOAT_EQ(r[i].t, i == 1 ? 4.0f + float(r[i].id) : 16.0f - float(r[i].id));
    }
}

TEST_F(RayControlTest, DisableClosestHitLeavesThePayloadToAnyHitAndMiss) {
    auto top = make_geometry_group(ctx, {square(5.0f, 1, true)});
    const auto r = cast(top, {ray(kOrigin, kForward, kRayFlagDisableClosestHit),
                              ray(kOrigin, kBackward, kRayFlagDisableClosestHit)});
    EXPECT_EQ(hits(r), (std::vector<int>{-1, 0})) << "closest hit ran, or miss did not";
    EXPECT_GE(r[0].anyhit_count, 1u);
}

TEST_F(RayControlTest, InstanceMasksInsideOneGeometryGroup) {
    for (const bool spheres : {false, true}) {
        auto near = spheres ? sphere(5.0f, 1) : square(5.0f, 1);
        auto far = spheres ? sphere(8.0f, 2) : square(8.0f, 2);
        near->set_visibility_mask(0x01);
        far->set_visibility_mask(0x06);
        auto top = make_geometry_group(ctx, {near, far});
        const auto r = cast(top, {ray(kOrigin, kForward), ray(kOrigin, kForward, 0, 0x01),
                                  ray(kOrigin, kForward, 0, 0x02), ray(kOrigin, kForward, 0, 0x08),
                                  ray(kOrigin, kForward, 0, 0x00),
                                  ray(kOrigin, kForward, 0, 0x02, 1),
                                  ray(kOrigin, kForward, 0, 0x08, 1),
                                  ray(kOrigin, kForward, 0, 0x02, 2)});
        EXPECT_EQ(ids(r), (std::vector<unsigned>{1, 1, 2, 0, 0, 0, 0, 0})) << "spheres " << spheres;
        EXPECT_EQ(occluded(r), (std::vector<unsigned>{0, 0, 0, 0, 0, 1, 0, 1}));
    }
}

TEST_F(RayControlTest, NodeMasksHideWholeSubgraphs) {
    // Two copies of one GeometryGroup under Transforms (instancing), masked 0x1 and 0x2; the
    // group itself carries a mask the root tests too.
    auto shared = make_geometry_group(ctx, {square(5.0f, 1)});
    auto first = ctx.create_transform(), second = ctx.create_transform();
    first->set_matrix(translation(0, 0, 0));
    second->set_matrix(translation(0, 0, 3));
    first->set_child(shared);
    second->set_child(shared);
    first->set_visibility_mask(0x1);
    second->set_visibility_mask(0x2);
    auto top = ctx.create_group();
    top->add_child(first);
    top->add_child(second);
    const auto r = cast(top, {ray(kOrigin, kForward), ray(kOrigin, kForward, 0, 0x2),
                              ray(kOrigin, kForward, 0, 0x4), ray(kOrigin, kForward, 0, 0x2, 1),
                              ray(kOrigin, kForward, 0, 0x4, 1)});
    EXPECT_EQ(hits(r), (std::vector<int>{1, 1, 0, -1, -1}));
    EXPECT_FLOAT_EQ(r[0].t, 5.0f);
    EXPECT_FLOAT_EQ(r[1].t, 8.0f);
    EXPECT_EQ(occluded(r), (std::vector<unsigned>{0, 0, 0, 1, 0}));

    shared->set_visibility_mask(0x4);  // now no ray that lacks 0x4 sees either copy
    const auto g = cast(top, {ray(kOrigin, kForward), ray(kOrigin, kForward, 0, 0x1),
                              ray(kOrigin, kForward, 0, 0x5)});
    EXPECT_EQ(hits(g), (std::vector<int>{1, 0, 1}));
    const auto root = cast(shared, {ray(kOrigin, kForward, 0, 0x3), ray(kOrigin, kForward, 0, 0x3, 1),
                                    ray(kOrigin, kForward, 0, 0x4, 1)});
    EXPECT_EQ(hits(root), (std::vector<int>{0, -1, -1}));
    EXPECT_EQ(occluded(root), (std::vector<unsigned>{0, 0, 1}));
}

TEST_F(RayControlTest, InstanceIdsAndTheHitsTransformMatrices) {
    auto instance = square(5.0f, 1, /*any_hit=*/true);
    instance->set_instance_id(42);
    auto group = make_geometry_group(ctx, {instance});
    auto inner = ctx.create_transform(), outer = ctx.create_transform();
    inner->set_matrix(translation(0, 0, 2));
    inner->set_instance_id(7);
    inner->set_child(group);
    outer->set_matrix(translation(1, 0, 0));
    outer->set_instance_id(9);
    outer->set_child(inner);
    auto top = ctx.create_group();
    top->add_child(outer);
    const auto r = cast(top, {ray(kOrigin, kForward)});
    ASSERT_EQ(r[0].hit, 1);
    EXPECT_FLOAT_EQ(r[0].t, 7.0f);
    EXPECT_EQ(r[0].instance_id, 7u) << "instance_id() is the innermost Transform's";
    EXPECT_EQ(r[0].geometry_instance_id, 42u);
    EXPECT_EQ(r[0].anyhit_instance_id, 7u);
    EXPECT_EQ(r[0].anyhit_geometry_id, 42u);
    const Matrix4x3 to_world = translation(1, 0, 2), to_object = translation(-1, 0, -2);
    for (int i = 0; i < 12; ++i) {
        EXPECT_FLOAT_EQ(r[0].to_world.m[i], to_world.m[i]) << i;
        EXPECT_FLOAT_EQ(r[0].to_object.m[i], to_object.m[i]) << i;
    }
    // Without a Transform: id 0 and identity matrices.
    const auto plain = cast(group, {ray(kOrigin, kForward)});
    ASSERT_EQ(plain[0].hit, 1);
    EXPECT_EQ(plain[0].instance_id, 0u);
    EXPECT_EQ(plain[0].geometry_instance_id, 42u);
    const Matrix4x3 identity = identity_matrix();
    for (int i = 0; i < 12; ++i) EXPECT_FLOAT_EQ(plain[0].to_object.m[i], identity.m[i]) << i;
}

TEST_F(RayControlTest, ContradictingFlagsAndWideMasksRaiseInvalidRayFlags) {
    auto top = make_geometry_group(ctx, {square(5.0f, 1)});
    const std::vector<ControlRay> bad = {
        ray(kOrigin, kForward, kRayFlagCullBackFacingTriangles | kRayFlagCullFrontFacingTriangles),
        ray(kOrigin, kForward, kRayFlagDisableAnyHit | kRayFlagEnforceAnyHit),
        ray(kOrigin, kForward, kRayFlagNone, 0x100),
        ray(kOrigin, kForward, 1u << 8),
        ray(kOrigin, kForward, kRayFlagEnforceAnyHit, kVisibilityMaskAll, 1),
        ray(kOrigin, kForward, kRayFlagCullDisabledAnyHit, kVisibilityMaskAll, 1),
        ray(kOrigin, kForward, kRayFlagCullBackFacingTriangles, kVisibilityMaskAll, 2),
        ray(kOrigin, kForward, kRayFlagNone, 0x1ff, 1)};
    const auto r = cast(top, bad, /*expect_clean=*/false);
    const LaunchReport& report = ctx.last_launch();
    ASSERT_EQ(report.exceptions.count(kExceptionInvalidRayFlags), 1u) << report.summary();
    EXPECT_EQ(report.exceptions.at(kExceptionInvalidRayFlags).count, bad.size());
    EXPECT_EQ(exception_name(kExceptionInvalidRayFlags), "invalid ray flags or visibility mask");
}

TEST_F(RayControlTest, HostSettersRefuseMasksAndFlagsOutOfRange) {
    auto group = ctx.create_geometry_group();
    group->set_name("walls");
    expect_error([&] { group->set_visibility_mask(0x100); }, {"GeometryGroup 'walls'", "0x00..0xff"});
    auto instance = square(5.0f, 1);
    expect_error([&] { instance->set_visibility_mask(0x1ff); }, {"GeometryInstance", "0x00..0xff"});
    expect_error([&] { instance->geometry()->set_flags(0x2); },
                 {"GeometryTriangles", "kGeometryFlagDisableAnyHit"});
    group->set_visibility_mask(0x00);
    EXPECT_EQ(group->visibility_mask(), 0u);
}

}  // namespace

// The scene graph (OptiX paper §3.2): transforms, nesting, instancing, selectors,
// per-ray-type roots, groups over many children, refit, and nodes with several parents.
#include <cmath>

#include "tests/programs/node_programs.h"
#include "tests/test_support.h"

namespace lucent_tests {
namespace {

class NodesTest : public CasterFixture {
  protected:
    std::shared_ptr<Program> sphere_hit() {
        return program(ctx, LUCENT_PROGRAM(common_sphere_hit));
    }

    /// A geometry group holding one sphere instance with material id `id`.
    std::shared_ptr<GeometryGroup> sphere_group(float4 sphere, unsigned id) {
        return make_geometry_group(ctx, {make_instance(ctx, make_spheres(ctx, {sphere}),
                                                       make_material(ctx, sphere_hit(), id))});
    }

    std::shared_ptr<Transform> transform(const Matrix4x3& m, std::shared_ptr<Node> child) {
        auto t = ctx.create_transform();
        t->set_matrix(m);
        t->set_child(std::move(child));
        return t;
    }

    static CastRay along_z(float x, float y, float z = -20) {
        return cast_ray(make_float3(x, y, z), make_float3(0, 0, 1));
    }
};

// ---- transforms -----------------------------------------------------------------

TEST_F(NodesTest, TransformMovesGeometryAndHitsAreInWorldSpace) {
    auto top = transform(translation(5, 0, 0), sphere_group(make_float4(0, 0, 0, 1), 1));
    const auto hits = cast(top, {cast_ray(make_float3(5, 0, -5), make_float3(0, 0, 1)),
                                 cast_ray(make_float3(0, 0, -5), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_NEAR(hits[0].t, 4.0f, kEps);
    EXPECT_FLOAT3_NEAR(hits[0].point, make_float3(5, 0, -1), kEps);
    EXPECT_FLOAT3_NEAR(hits[0].normal, make_float3(0, 0, -1), kEps);
    EXPECT_FLOAT3_NEAR(hits[0].object_point, make_float3(0, 0, -1), kEps);
    EXPECT_EQ(hits[1].hit, 0) << "the sphere moved away from the origin";
}

TEST_F(NodesTest, NonUniformScaleTransformsNormalsByTheInverseTranspose) {
    // Sphere stretched 2x along x, centred at (5, 0, 0): an ellipsoid.
    Matrix4x3 m = scaling(2, 1, 1);
    m.m[3] = 5;
    auto top = transform(m, sphere_group(make_float4(0, 0, 0, 1), 1));
    // In object space the ray runs at x = -1/sqrt(2) and enters at z = -1/sqrt(2).
    const float s = std::sqrt(0.5f);
    const auto hits = cast(top, {cast_ray(make_float3(5 - 2 * s, 0, -5), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_NEAR(hits[0].t, 5 - s, kEps) << "t is the same parameter in world and object space";
    EXPECT_FLOAT3_NEAR(hits[0].point, make_float3(5 - 2 * s, 0, -s), kEps);
    EXPECT_FLOAT3_NEAR(hits[0].object_point, make_float3(-s, 0, -s), kEps);
    // Object normal (-s, 0, -s) times M^-T = (-s / 2, 0, -s), normalised.
    const float3 expected = normalize(make_float3(-s / 2, 0, -s));
    EXPECT_FLOAT3_NEAR(hits[0].normal, expected, kEps);
}

TEST_F(NodesTest, NestedTransformsComposeOuterTimesInner) {
    // world = translate(5,0,0) * scale(2) * object: a radius-2 sphere centred at x = 5.
    // The other order would centre it at x = 10 and the ray would miss.
    auto inner = transform(scaling(2, 2, 2), sphere_group(make_float4(0, 0, 0, 1), 1));
    auto top = transform(translation(5, 0, 0), inner);
    const auto hits = cast(top, {cast_ray(make_float3(5, 0, -10), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_NEAR(hits[0].t, 8.0f, kEps);
    EXPECT_FLOAT3_NEAR(hits[0].point, make_float3(5, 0, -2), kEps);
    EXPECT_FLOAT3_NEAR(hits[0].normal, make_float3(0, 0, -1), kEps);
    EXPECT_FLOAT3_NEAR(hits[0].object_point, make_float3(0, 0, -1), kEps);
}

TEST_F(NodesTest, TransposedMatrixInputIsColumnMajor) {
    // Column-major translation by (0, 3, 0): the translation sits in the last column.
    const float column_major[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 3, 0};
    auto t = ctx.create_transform();
    t->set_matrix(column_major, /*transpose=*/true);
    t->set_child(sphere_group(make_float4(0, 0, 0, 1), 1));
    EXPECT_FLOAT_EQ(t->matrix().m[7], 3.0f) << "stored row-major: row 1, column 3";
    const auto hits = cast(t, {along_z(0, 3), along_z(0, 0)});
    EXPECT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[1].hit, 0);
}

TEST_F(NodesTest, ChangedMatrixTakesEffectAtTheNextLaunch) {
    auto t = transform(translation(0, 0, 0), sphere_group(make_float4(0, 0, 0, 1), 1));
    EXPECT_EQ(cast(t, {along_z(4, 0)})[0].hit, 0);
    t->set_matrix(translation(4, 0, 0));
    const auto hits = cast(t, {along_z(4, 0)});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_FLOAT3_NEAR(hits[0].point, make_float3(4, 0, -1), kEps);
}

/// Rotation by 90 degrees about y: object +z becomes world +x, object +x becomes world -z.
Matrix4x3 rotation_y90() {
    return Matrix4x3{{0, 0, 1, 0, 0, 1, 0, 0, -1, 0, 0, 0}};
}

TEST_F(NodesTest, TrianglesUnderARotationHaveWorldSpaceNormalsAndHitPoints) {
    // The square at object z = 2 becomes the world plane x = 2.
    auto gg = make_geometry_group(
        ctx,
        {make_instance(ctx, make_triangles(ctx, square_at(2)),
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1))});
    auto top = transform(rotation_y90(), gg);
    const auto hits = cast(top, {cast_ray(make_float3(-5, 0.1f, 0.3f), make_float3(1, 0, 0))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_NEAR(hits[0].t, 7.0f, kEps);
    EXPECT_FLOAT3_NEAR(hits[0].point, make_float3(2, 0.1f, 0.3f), kEps);
    EXPECT_NEAR(std::fabs(hits[0].normal.x), 1.0f, kEps) << "world normal of the plane x = 2";
    EXPECT_FLOAT3_NEAR(hits[0].object_point, make_float3(-0.3f, 0.1f, 2), kEps);
}

TEST_F(NodesTest, AttributeProgramBelowATransformSeesTheHitsTransformAndPrimitive) {
    // No any-hit program: attributes may be computed after traversal, when the traversal
    // position has already left the Transform. They must still see the hit's transform.
    std::vector<float3> vertices = square_at(9, 20, 30, 20, 30);  // prims 0, 1: off the ray
    const auto hit_square = square_at(2);                         // prims 2, 3: on the ray
    vertices.insert(vertices.end(), hit_square.begin(), hit_square.end());
    auto triangles = make_triangles(ctx, vertices);
    triangles->set_attribute_program(program(ctx, LUCENT_PROGRAM(nt_space_attributes)));
    auto gg = make_geometry_group(
        ctx, {make_instance(ctx, triangles,
                            make_material(ctx, program(ctx, LUCENT_PROGRAM(nt_space_hit)), 1))});
    auto top = transform(rotation_y90(), gg);
    // Trace twice so the second trace starts from a used frame (no stale state).
    const auto hits = cast(top, {cast_ray(make_float3(-5, 0.1f, 0.3f), make_float3(1, 0, 0)),
                                 cast_ray(make_float3(-5, 0.1f, 0.3f), make_float3(1, 0, 0))});
    for (const TestPayload& hit : hits) {
        ASSERT_EQ(hit.hit, 1);
        EXPECT_NEAR(hit.t, 7.0f, kEps);
        {
            SCOPED_TRACE(
                "object_to_world_normal in the attribute program uses the hit's transform");
            EXPECT_FLOAT3_NEAR(hit.normal, make_float3(1, 0, 0), kEps);
        }
        EXPECT_EQ(hit.prim, hit.anyhit_count) << "primitive_index() equals the prim argument";
        EXPECT_GE(hit.anyhit_count, 2u) << "the hit is on the second square";
        {
            SCOPED_TRACE(
                "current_ray() in the attribute program is in object space, like intersection");
            EXPECT_FLOAT3_NEAR(hit.object_point, make_float3(-0.3f, 0.1f, -5), kEps);
        }
    }
}

TEST_F(NodesTest, AnyHitBelowATransformSeesTheObjectRayAndWorldT) {
    // translate(0,0,10) * scale(2): a radius-2 sphere centred at z = 10.
    Matrix4x3 m = scaling(2, 2, 2);
    m.m[11] = 10;
    auto material = make_material(ctx, sphere_hit(), 1);
    material->set_any_hit(0, program(ctx, LUCENT_PROGRAM(nt_anyhit_record)));
    auto gg = make_geometry_group(
        ctx, {make_instance(ctx, make_spheres(ctx, {make_float4(0, 0, 0, 1)}), material)});
    const auto hits =
        cast(transform(m, gg), {cast_ray(make_float3(0, 0, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_NEAR(hits[0].t, 8.0f, kEps);
    EXPECT_NEAR(hits[0].anyhit_t, 8.0f, kEps);
    EXPECT_NEAR(hits[0].uv.x, -5.0f, kEps) << "object-space origin z";
    EXPECT_NEAR(hits[0].uv.y, 0.5f, kEps) << "object-space direction z (not renormalised)";
}

TEST_F(NodesTest, NearestHitWinsAcrossDifferentlyScaledInstances) {
    // A radius-3 sphere (unit sphere scaled 3x) centred at z = 10, front at z = 7, and a
    // unit sphere at z = 5, front at z = 4. Child order must not matter.
    Matrix4x3 big = scaling(3, 3, 3);
    big.m[11] = 10;
    auto unit = sphere_group(make_float4(0, 0, 0, 1), 1);
    auto near = transform(translation(0, 0, 5), unit);
    auto far = transform(big, sphere_group(make_float4(0, 0, 0, 1), 2));
    for (bool near_first : {true, false}) {
        auto top = ctx.create_group();
        top->add_child(near_first ? std::shared_ptr<Node>(near) : far);
        top->add_child(near_first ? std::shared_ptr<Node>(far) : near);
        const auto hits = cast(top, {along_z(0, 0, 0), along_z(2, 0, 0)});
        ASSERT_EQ(hits[0].hit, 1);
        EXPECT_EQ(hits[0].id, 1u) << "near_first = " << near_first;
        EXPECT_NEAR(hits[0].t, 4.0f, kEps);
        ASSERT_EQ(hits[1].hit, 1) << "x = 2 passes beside the unit sphere, into the big one";
        EXPECT_EQ(hits[1].id, 2u);
        EXPECT_NEAR(hits[1].t, 10.0f - std::sqrt(5.0f), 1e-3f);
    }
}

TEST_F(NodesTest, DeepHierarchyOfGroupsAndTransformsComposes) {
    // Group -> Transform(+x 1) -> Group -> Transform(+x 2) -> Transform(+y 3) -> GeometryGroup.
    auto inner = transform(translation(0, 3, 0), sphere_group(make_float4(0, 0, 0, 0.5f), 4));
    auto middle_group = ctx.create_group();
    middle_group->add_child(transform(translation(2, 0, 0), inner));
    auto top = ctx.create_group();
    top->add_child(transform(translation(1, 0, 0), middle_group));
    const auto hits = cast(top, {along_z(3, 3), along_z(0, 0)});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].id, 4u);
    EXPECT_FLOAT3_NEAR(hits[0].point, make_float3(3, 3, -0.5f), kEps);
    EXPECT_FLOAT3_NEAR(hits[0].object_point, make_float3(0, 0, -0.5f), kEps);
    EXPECT_EQ(hits[1].hit, 0);
}

TEST_F(NodesTest, EmptyGroupsAreValidRootsThatMissEverything) {
    EXPECT_EQ(cast(ctx.create_group(), {along_z(0, 0)})[0].hit, 0);
    EXPECT_EQ(cast(ctx.create_geometry_group(), {along_z(0, 0)})[0].hit, 0);
}

TEST_F(NodesTest, ChildAddedToAGroupAfterALaunchIsSeenAtTheNextLaunch) {
    auto top = ctx.create_group();
    top->add_child(sphere_group(make_float4(0, 0, 0, 1), 1));
    EXPECT_EQ(cast(top, {along_z(5, 0)})[0].hit, 0);
    top->add_child(sphere_group(make_float4(5, 0, 0, 1), 2));  // no explicit mark_dirty
    const auto hits = cast(top, {along_z(5, 0), along_z(0, 0)});
    EXPECT_EQ(hits[0].id, 2u);
    EXPECT_EQ(hits[1].id, 1u);
    top->remove_child(0);
    EXPECT_EQ(cast(top, {along_z(0, 0)})[0].hit, 0) << "the removed child is gone";
}

TEST_F(NodesTest, InstanceAddedToAGeometryGroupAfterALaunchIsSeenAtTheNextLaunch) {
    auto gg = sphere_group(make_float4(0, 0, 0, 1), 1);
    EXPECT_EQ(cast(gg, {along_z(5, 0)})[0].hit, 0);
    gg->add_child(make_instance(ctx, make_spheres(ctx, {make_float4(5, 0, 0, 1)}),
                                make_material(ctx, sphere_hit(), 2)));
    EXPECT_EQ(cast(gg, {along_z(5, 0)})[0].id, 2u);
}

TEST_F(NodesTest, InstancedGeometryGroupUnderTwoTransformsIsHitTwice) {
    auto shared = sphere_group(make_float4(0, 0, 0, 1), 7);
    auto top = ctx.create_group();
    top->add_child(transform(translation(-3, 0, 0), shared));
    top->add_child(transform(translation(3, 0, 0), shared));
    const auto hits = cast(top, {along_z(-3, 0), along_z(3, 0), along_z(0, 0)});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].id, 7u);
    EXPECT_FLOAT3_NEAR(hits[0].point, make_float3(-3, 0, -1), kEps);
    EXPECT_FLOAT3_NEAR(hits[0].object_point, make_float3(0, 0, -1), kEps);
    ASSERT_EQ(hits[1].hit, 1);
    EXPECT_FLOAT3_NEAR(hits[1].point, make_float3(3, 0, -1), kEps);
    EXPECT_FLOAT3_NEAR(hits[1].object_point, make_float3(0, 0, -1), kEps);
    EXPECT_EQ(hits[2].hit, 0) << "nothing between the two copies";
}

TEST_F(NodesTest, GeometryInstanceWithSeveralParentsIsHitUnderEach) {
    auto instance = make_instance(ctx, make_spheres(ctx, {make_float4(0, 0, 0, 1)}),
                                  make_material(ctx, sphere_hit(), 11));
    auto left = make_geometry_group(ctx, {instance});
    auto right = make_geometry_group(ctx, {instance});
    auto top = ctx.create_group();
    top->add_child(transform(translation(-3, 0, 0), left));
    top->add_child(transform(translation(3, 0, 0), right));
    const auto hits = cast(top, {along_z(-3, 0), along_z(3, 0), along_z(0, 0)});
    EXPECT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].id, 11u);
    EXPECT_EQ(hits[1].hit, 1);
    EXPECT_EQ(hits[1].id, 11u);
    EXPECT_EQ(hits[2].hit, 0);
}

// ---- selectors ------------------------------------------------------------------

class SelectorTest : public NodesTest {
  protected:
    /// Two children with the same sphere but different material ids (1 and 2).
    std::shared_ptr<Selector> selector(const ProgramDesc& visit) {
        auto s = ctx.create_selector();
        s->set_visit_program(program(ctx, visit));
        s->add_child(sphere_group(make_float4(0, 0, 5, 1), 1));
        s->add_child(sphere_group(make_float4(0, 0, 5, 1), 2));
        return s;
    }
};

TEST_F(SelectorTest, VisitProgramPicksAChildFromTheRayDirection) {
    auto top = selector(LUCENT_PROGRAM(nt_visit_by_direction));
    const auto hits = cast(top, {cast_ray(make_float3(-0.1f, 0, 0), make_float3(0.02f, 0, 1)),
                                 cast_ray(make_float3(0.1f, 0, 0), make_float3(-0.02f, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].id, 1u);
    ASSERT_EQ(hits[1].hit, 1);
    EXPECT_EQ(hits[1].id, 2u);
}

TEST_F(SelectorTest, VisitProgramPicksAChildFromTheLaunchIndex) {
    auto top = selector(LUCENT_PROGRAM(nt_visit_by_launch_index));
    const auto hits = cast(top, std::vector<CastRay>(6, along_z(0, 0)));
    for (unsigned i = 0; i < 6; ++i) {
        ASSERT_EQ(hits[i].hit, 1) << "ray " << i;
        EXPECT_EQ(hits[i].id, 1u + i % 2) << "ray " << i;
    }
}

TEST_F(SelectorTest, IndexBeyondTheChildrenSelectsNone) {
    auto top = selector(LUCENT_PROGRAM(nt_visit_by_choice));
    (*top->visit_program())["choice"] = 1u;
    EXPECT_EQ(cast(top, {along_z(0, 0)})[0].id, 2u);
    (*top->visit_program())["choice"] = 2u;  // == child count: no child
    EXPECT_EQ(cast(top, {along_z(0, 0)})[0].hit, 0);
    (*top->visit_program())["choice"] = 1000u;
    EXPECT_EQ(cast(top, {along_z(0, 0)})[0].hit, 0);
}

TEST_F(SelectorTest, SelectorUnderATransformSeesTheObjectSpaceRay) {
    // The transform mirrors x, so a ray going towards +x in world goes towards -x below it.
    Matrix4x3 mirror = scaling(-1, 1, 1);
    auto top = transform(mirror, selector(LUCENT_PROGRAM(nt_visit_by_direction)));
    const auto hits = cast(top, {cast_ray(make_float3(-0.1f, 0, 0), make_float3(0.02f, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].id, 2u);
}

TEST_F(SelectorTest, SelectorAsAChildOfAGroupIsTraversed) {
    // The group's hierarchy over its children must give the selector its children's bounds.
    auto top = ctx.create_group();
    top->add_child(sphere_group(make_float4(8, 0, 5, 1), 3));
    top->add_child(selector(LUCENT_PROGRAM(nt_visit_by_launch_index)));
    const auto hits = cast(top, {along_z(0, 0), along_z(0, 0), along_z(8, 0)});
    EXPECT_EQ(hits[0].id, 1u);
    EXPECT_EQ(hits[1].id, 2u);
    EXPECT_EQ(hits[2].id, 3u);
}

// ---- one root per ray type -------------------------------------------------------

TEST_F(NodesTest, ShadowRaysTraverseADifferentRootThanRadianceRays) {
    ctx.set_ray_type<ShadowPayload>(1, "shadow", /*expects_closest_hit=*/false);
    ctx.set_miss_program(1, program(ctx, LUCENT_PROGRAM(nt_shadow_miss)));
    auto shadow_hit = program(ctx, LUCENT_PROGRAM(nt_shadow_hit));
    auto visible = make_material(ctx, sphere_hit(), 1);
    visible->set_closest_hit(1, shadow_hit);
    auto occluder = make_material(ctx, sphere_hit(), 2);
    occluder->set_closest_hit(1, shadow_hit);
    // Radiance sees a sphere at z = 5; shadow rays see only a sphere at z = 10.
    auto radiance_root = make_geometry_group(
        ctx, {make_instance(ctx, make_spheres(ctx, {make_float4(0, 0, 5, 1)}), visible)});
    auto shadow_root = make_geometry_group(
        ctx, {make_instance(ctx, make_spheres(ctx, {make_float4(0, 0, 10, 1)}), occluder)});

    auto gen = program(ctx, LUCENT_PROGRAM(nt_two_roots));
    ctx.set_ray_generation_program(0, gen);
    (*gen)["radiance_root"] = radiance_root;
    (*gen)["shadow_root"] = shadow_root;
    (*gen)["rays"] = input_buffer(ctx, std::vector<CastRay>{along_z(0, 0, 0), along_z(5, 0, 0)});
    auto radiance = ctx.create_buffer<TestPayload>(BufferType::kOutput, 2);
    auto shadow = ctx.create_buffer<ShadowPayload>(BufferType::kOutput, 2);
    (*gen)["radiance"] = radiance;
    (*gen)["shadow"] = shadow;
    ctx.launch(0, 2);

    const auto r = read_buffer<TestPayload>(*radiance);
    const auto s = read_buffer<ShadowPayload>(*shadow);
    ASSERT_EQ(r[0].hit, 1);
    EXPECT_EQ(r[0].id, 1u);
    EXPECT_NEAR(r[0].t, 4.0f, kEps);
    ASSERT_EQ(s[0].hit, 1);
    EXPECT_EQ(s[0].id, 2u) << "the shadow ray must not see the radiance root's sphere";
    EXPECT_NEAR(s[0].t, 9.0f, kEps);
    EXPECT_EQ(r[1].hit, 0);
    EXPECT_EQ(s[1].hit, 0);
}

// ---- groups over many children ------------------------------------------------------

class ManyChildrenTest : public NodesTest {
  protected:
    static constexpr int kGrid = 8;
    static float4 sphere_of(int i, int j) {
        return make_float4(2.0f * i, 2.0f * j, 10.0f + float((i + j) % 3), 0.8f);
    }
    /// Brute force: a +z ray at (x, y) can only hit the sphere of its grid cell.
    static void expected_hit(float x, float y, int& id, float& t) {
        id = -1;
        t = -1;
        for (int i = 0; i < kGrid; ++i)
            for (int j = 0; j < kGrid; ++j) {
                const float4 s = sphere_of(i, j);
                const float dx = x - s.x, dy = y - s.y, d2 = dx * dx + dy * dy;
                if (d2 >= s.w * s.w) continue;
                const float ti = (s.z - std::sqrt(s.w * s.w - d2)) - (-20.0f);
                if (id < 0 || ti < t) {
                    id = i * kGrid + j;
                    t = ti;
                }
            }
    }
    /// 64 children, half geometry groups placed directly, half behind translations.
    std::shared_ptr<Group> many() {
        auto group = ctx.create_group();
        auto origin_sphere = make_spheres(ctx, {make_float4(0, 0, 0, 0.8f)});
        auto material = ctx.create_material();
        material->set_closest_hit(0, sphere_hit());
        for (int i = 0; i < kGrid; ++i)
            for (int j = 0; j < kGrid; ++j) {
                const float4 s = sphere_of(i, j);
                const unsigned id = unsigned(i * kGrid + j);
                std::shared_ptr<GeometryInstance> instance;
                std::shared_ptr<Node> child;
                if (id % 2 == 0) {
                    instance = make_instance(ctx, make_spheres(ctx, {s}), material);
                    child = make_geometry_group(ctx, {instance});
                } else {
                    instance = make_instance(ctx, origin_sphere, material);
                    child =
                        transform(translation(s.x, s.y, s.z), make_geometry_group(ctx, {instance}));
                }
                // The instance's id wins over the material's (closest-hit scope order).
                (*instance)["id"] = id;
                group->add_child(child);
            }
        return group;
    }
    std::vector<CastRay> grid_rays() {
        std::vector<CastRay> rays;
        for (int a = 0; a < 40; ++a)
            for (int b = 0; b < 40; ++b)
                rays.push_back(along_z(-1.3f + 0.43f * a, -1.1f + 0.41f * b));
        return rays;
    }
};

TEST_F(ManyChildrenTest, BvhOverChildrenMatchesBruteForce) {
    auto top = many();
    const auto rays = grid_rays();
    const auto bvh_hits = cast(top, rays);

    top->acceleration()->set_builder(Builder::kNone);
    top->acceleration()->mark_dirty();
    const auto flat_hits = cast(top, rays);

    int hit_count = 0;
    for (size_t r = 0; r < rays.size(); ++r) {
        int id;
        float t;
        expected_hit(rays[r].origin.x, rays[r].origin.y, id, t);
        const testing::Message where = testing::Message() << "ray at (" << rays[r].origin.x << ", "
                                                          << rays[r].origin.y << ")";
        if (id < 0) {
            EXPECT_EQ(bvh_hits[r].hit, 0) << where;
            EXPECT_EQ(flat_hits[r].hit, 0) << where;
            continue;
        }
        ++hit_count;
        EXPECT_EQ(bvh_hits[r].hit, 1) << where;
        EXPECT_EQ(bvh_hits[r].id, unsigned(id)) << where;
        EXPECT_NEAR(bvh_hits[r].t, t, 1e-3f) << where;
        EXPECT_EQ(flat_hits[r].hit, 1) << where << " (Builder::kNone)";
        EXPECT_EQ(flat_hits[r].id, unsigned(id)) << where << " (Builder::kNone)";
        EXPECT_NEAR(flat_hits[r].t, t, 1e-3f) << where << " (Builder::kNone)";
    }
    EXPECT_GT(hit_count, 100) << "the ray grid should hit many spheres";
}

// ---- refit ---------------------------------------------------------------------------

class RefitTest : public NodesTest {
  protected:
    /// A 4x4 grid of quads over [0,4]^2 at z = 2 (32 triangles).
    static std::vector<float3> grid_vertices() {
        std::vector<float3> v;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) {
                const auto quad = square_at(2, float(i), float(i + 1), float(j), float(j + 1));
                v.insert(v.end(), quad.begin(), quad.end());
            }
        return v;
    }
    /// Moved: shifted by 3 along x and lifted onto the tilted plane z = 4 + y / 4.
    static void move(float3* v, size_t n) {
        for (size_t k = 0; k < n; ++k) v[k] = make_float3(v[k].x + 3, v[k].y, 4 + 0.25f * v[k].y);
    }
    std::vector<CastRay> rays() {
        std::vector<CastRay> r;
        for (int a = 0; a < 16; ++a)
            for (int b = 0; b < 8; ++b)
                r.push_back(along_z(0.23f + 0.45f * a, 0.21f + 0.45f * b, 0));
        return r;
    }
    void refit_and_rebuild(Builder builder);
};

/// Traces the grid, moves it, and traces it refitted and rebuilt, with `builder` for the
/// grid's GeometryGroup.
void RefitTest::refit_and_rebuild(Builder builder) {
    auto triangles = make_triangles(ctx, grid_vertices());
    auto gg = make_geometry_group(
        ctx,
        {make_instance(ctx, triangles,
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1))});
    gg->acceleration()->set_builder(builder);
    auto top = ctx.create_group();
    top->add_child(gg);
    const auto ray_list = rays();
    const auto before = cast(top, ray_list);
    for (size_t r = 0; r < ray_list.size(); ++r) {
        const float x = ray_list[r].origin.x, y = ray_list[r].origin.y;
        const bool inside = x < 4 && y < 4;
        EXPECT_EQ(before[r].hit, inside ? 1 : 0) << "before moving, ray " << r;
        if (inside) {
            EXPECT_NEAR(before[r].t, 2.0f, kEps);
        }
    }

    // Move the vertices; both accelerations whose bounds changed are marked dirty.
    Buffer& vertices = *triangles->vertices();
    move(vertices.map<float3>(), vertices.count());
    vertices.unmap();
    for (const auto& accel : {gg->acceleration(), top->acceleration()}) {
        accel->set_refit(true);
        accel->mark_dirty();
    }
    const auto refitted = cast(top, ray_list);

    for (const auto& accel : {gg->acceleration(), top->acceleration()}) {
        accel->set_refit(false);
        accel->mark_dirty();
    }
    const auto rebuilt = cast(top, ray_list);

    for (size_t r = 0; r < ray_list.size(); ++r) {
        const float x = ray_list[r].origin.x, y = ray_list[r].origin.y;
        const bool inside = x > 3 && x < 7 && y < 4;
        EXPECT_EQ(refitted[r].hit, inside ? 1 : 0) << "refit, ray at " << x << ", " << y;
        EXPECT_EQ(rebuilt[r].hit, inside ? 1 : 0) << "rebuild, ray at " << x << ", " << y;
        if (!inside) continue;
        EXPECT_NEAR(refitted[r].t, 4 + 0.25f * y, 1e-3f) << "refit, ray at " << x << ", " << y;
        EXPECT_NEAR(rebuilt[r].t, 4 + 0.25f * y, 1e-3f) << "rebuild, ray at " << x << ", " << y;
        EXPECT_EQ(refitted[r].prim, rebuilt[r].prim);
    }
}

TEST_F(RefitTest, RefitAfterMovingVerticesGivesTheSameHitsAsARebuild) {
    refit_and_rebuild(Builder::kBinnedSah);
}

TEST_F(RefitTest, DefaultBuilderRefitsAndRebuildsAlike) {
    // Builder::kAuto: on the CUDA backend the GPU's binned-SAH build and the GPU refit.
    EXPECT_EQ(ctx.create_acceleration()->builder(), Builder::kAuto);
    refit_and_rebuild(Builder::kAuto);
}

TEST_F(RefitTest, GpuBuilderAndItsRefitGiveTheSameHits) {
    // On the CUDA backend the grid's BVH is built (H-PLOC) and refitted on the GPU; on the
    // CPU, Builder::kGpuHploc builds binned SAH.
    refit_and_rebuild(Builder::kGpuHploc);
}

TEST_F(RefitTest, GpuBuilderTakesAChainOfTriangles) {
    // Triangles in a geometric progression make agglomerative builds chain: the GPU build
    // must stay within the traversal stack, or the CUDA backend fall back to its host build
    // (GpuBvhTooDeep); either way every triangle is found.
    std::vector<float3> vertices;
    std::vector<CastRay> rays;
    for (int i = 0; i < 150; ++i) {
        const float x = std::pow(1.2f, float(i)), s = 0.1f * x;
        vertices.insert(vertices.end(), {make_float3(x, 0, 0), make_float3(x + s, 0, 0),
                                         make_float3(x, s, 0)});
        rays.push_back(along_z(x + 0.02f * x, 0.02f * x));
    }
    auto gg = make_geometry_group(
        ctx, {make_instance(ctx, make_triangles(ctx, vertices),
                            make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)),
                                          1))});
    gg->acceleration()->set_builder(Builder::kGpuHploc);
    const auto hits = cast(gg, rays);
    for (size_t r = 0; r < rays.size(); ++r) {
        ASSERT_EQ(hits[r].hit, 1) << "ray " << r;
        EXPECT_EQ(hits[r].prim, unsigned(r)) << "ray " << r;
        EXPECT_NEAR(hits[r].t, 20.0f, 1e-3f) << "ray " << r;
    }
}

TEST_F(RefitTest, MixedTrianglesAndSpheresHitTheSameWithAndWithoutAHierarchy) {
    // One geometry group holding a triangle grid and a row of spheres (the generic path
    // that mixes built-in and custom primitives), traced with Builder::kBinnedSah and kNone.
    auto triangles = make_triangles(ctx, grid_vertices());
    std::vector<float4> balls;
    for (int i = 0; i < 10; ++i)
        balls.push_back(make_float4(0.4f * i, 1.0f + 0.2f * i, 1.0f + 0.3f * i, 0.3f));
    auto gg = make_geometry_group(
        ctx,
        {make_instance(ctx, triangles,
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1)),
         make_instance(ctx, make_spheres(ctx, balls), make_material(ctx, sphere_hit(), 2))});
    const auto ray_list = rays();
    const auto with_bvh = cast(gg, ray_list);
    gg->acceleration()->set_builder(Builder::kNone);
    const auto flat = cast(gg, ray_list);
    int spheres_hit = 0;
    for (size_t r = 0; r < ray_list.size(); ++r) {
        EXPECT_EQ(with_bvh[r].hit, flat[r].hit) << "ray " << r;
        EXPECT_EQ(with_bvh[r].id, flat[r].id) << "ray " << r;
        EXPECT_EQ(with_bvh[r].prim, flat[r].prim) << "ray " << r;
        EXPECT_NEAR(with_bvh[r].t, flat[r].t, 1e-5f) << "ray " << r;
        spheres_hit += with_bvh[r].id == 2;
    }
    EXPECT_GT(spheres_hit, 3) << "some rays should reach a sphere before the grid";
}

TEST_F(RefitTest, RefitAfterMovingCustomPrimitivesFollowsTheirNewBounds) {
    auto spheres = make_spheres(ctx, {make_float4(0, 0, 5, 1), make_float4(3, 0, 5, 1)});
    auto gg = make_geometry_group(
        ctx, {make_instance(ctx, spheres, make_material(ctx, sphere_hit(), 1))});
    gg->acceleration()->set_refit(true);
    EXPECT_EQ(cast(gg, {along_z(10, 0, 0)})[0].hit, 0);
    // Move the second sphere far to the right: its box must move with it.
    (*spheres)["spheres"] =
        input_buffer(ctx, std::vector<float4>{make_float4(0, 0, 5, 1), make_float4(10, 0, 7, 1)});
    gg->acceleration()->mark_dirty();
    const auto hits = cast(gg, {along_z(10, 0, 0), along_z(3, 0, 0), along_z(0, 0, 0)});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_NEAR(hits[0].t, 6.0f, kEps);
    EXPECT_EQ(hits[0].prim, 1u);
    EXPECT_EQ(hits[1].hit, 0) << "nothing is left at x = 3";
    EXPECT_EQ(hits[2].hit, 1);
}

}  // namespace
}  // namespace lucent_tests

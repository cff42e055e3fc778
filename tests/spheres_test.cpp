// Built-in spheres (GeometrySpheres, OptiX's OPTIX_PRIMITIVE_TYPE_SPHERE): hits and their
// attributes against a double-precision reference (grazing rays, thin radii far away, rays
// from inside), both intersections offered to any-hit, transforms, groups mixing spheres and
// triangles, occlusion, culls, and every misuse refused with a message naming the fix. Each
// case runs on the suite's backend (LUCENT_TEST_BACKEND), so CPU and GPU are held alike.
#include <cmath>
#include <random>

#include "tests/programs/sphere_programs.h"
#include "tests/test_support.h"

namespace {

using namespace lucent;
using namespace lucent_tests;

/// The exact intersections of a float ray with a float sphere, in double precision.
struct ReferenceHit {
    bool hit = false;
    double t0 = 0, t1 = 0;
};
ReferenceHit reference_sphere(float3 o, float3 d, float3 c, float r) {
    const double f[3] = {double(o.x) - c.x, double(o.y) - c.y, double(o.z) - c.z};
    const double dd[3] = {d.x, d.y, d.z};
    const double a = dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2];
    const double b = -(f[0] * dd[0] + f[1] * dd[1] + f[2] * dd[2]);
    const double cc = f[0] * f[0] + f[1] * f[1] + f[2] * f[2] - double(r) * r;
    const double disc = b * b - a * cc;
    ReferenceHit h;
    if (disc < 0) return h;
    h.hit = true;
    h.t0 = (b - std::sqrt(disc)) / a;
    h.t1 = (b + std::sqrt(disc)) / a;
    return h;
}

class SpheresTest : public testing::Test {
  protected:
    SpheresTest() : ctx(test_context_options()) {
        ctx.set_entry_point_count(1);
        ctx.set_ray_type<SpherePayload>(0, "radiance");
        ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(sphere_miss)));
        ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(sphere_cast)));
    }

    std::shared_ptr<GeometrySpheres> spheres(const std::vector<float4>& s) {
        std::vector<float3> centers;
        std::vector<float> radii;
        for (const float4& v : s) {
            centers.push_back(make_float3(v.x, v.y, v.z));
            radii.push_back(v.w);
        }
        auto g = ctx.create_geometry_spheres();
        g->set_centers(input_buffer(ctx, centers));
        g->set_radii(input_buffer(ctx, radii));
        return g;
    }
    std::shared_ptr<Material> material(unsigned id, bool any_hit = false, bool ignore = false) {
        auto m = make_material(ctx, program(ctx, LUCENT_PROGRAM(sphere_hit)), id);
        if (any_hit) {
            m->set_any_hit(0, program(ctx, LUCENT_PROGRAM(sphere_any_hit)));
            (*m)["ignore"] = ignore ? 1u : 0u;
        }
        return m;
    }
    std::shared_ptr<GeometryGroup> group_of(std::shared_ptr<GeometryBase> g,
                                            std::shared_ptr<Material> m) {
        return make_geometry_group(ctx, {make_instance(ctx, std::move(g), std::move(m))});
    }

    std::vector<SpherePayload> cast(std::shared_ptr<Node> top, const std::vector<SphereRay>& rays) {
        auto results =
            ctx.create_buffer<SpherePayload>(BufferType::kOutput, unsigned(rays.size()));
        auto gen = ctx.ray_generation_program(0);
        (*gen)["top"] = top;
        (*gen)["rays"] = input_buffer(ctx, rays);
        (*gen)["results"] = results;
        ctx.launch(0, unsigned(rays.size()));
        EXPECT_EQ(ctx.last_launch().exception_count(), 0u) << ctx.last_launch().summary();
        return read_buffer<SpherePayload>(*results);
    }
    static SphereRay ray(float3 o, float3 d, float tmin = 0.0f, float tmax = kInfinity,
                         unsigned flags = kRayFlagNone, unsigned occlusion = 0) {
        return SphereRay{o, d, tmin, tmax, flags, occlusion};
    }

    Context ctx;
};

TEST_F(SpheresTest, HitsReportTheNearSideItsNormalAndPrimitive) {
    auto top = group_of(spheres({make_float4(0, 0, 10, 2), make_float4(5, 0, 10, 1)}), material(7));
    auto r = cast(top, {ray(make_float3(0, 0, 0), make_float3(0, 0, 1)),
                        ray(make_float3(5, 0, 0), make_float3(0, 0, 2)),
                        ray(make_float3(0, 3, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(r[0].hit, 1);
    EXPECT_EQ(r[0].id, 7u);
    EXPECT_EQ(r[0].prim, 0u);
    EXPECT_FLOAT_EQ(r[0].t, 8.0f);
    EXPECT_NEAR(r[0].object_normal.z, -1.0f, 1e-6f);
    EXPECT_EQ(r[0].entering, 1u);
    ASSERT_EQ(r[1].hit, 1);
    EXPECT_EQ(r[1].prim, 1u);
    EXPECT_FLOAT_EQ(r[1].t, 4.5f);  // t in units of the unnormalised direction
    EXPECT_EQ(r[2].hit, 0);
}

TEST_F(SpheresTest, RaysFromInsideHitTheFarSideWithAnOutwardNormal) {
    auto top = group_of(spheres({make_float4(1, 2, 3, 4)}), material(1));
    auto r = cast(top, {ray(make_float3(1, 2, 3), make_float3(1, 0, 0)),
                        ray(make_float3(2, 2, 3), make_float3(0, -1, 0)),
                        ray(make_float3(1, 2, 6.5f), make_float3(0, 0, -1))});
    for (const SpherePayload& p : r) {
        ASSERT_EQ(p.hit, 1);
        EXPECT_EQ(p.entering, 0u);
    }
    EXPECT_FLOAT_EQ(r[0].t, 4.0f);
    EXPECT_NEAR(r[0].object_normal.x, 1.0f, 1e-6f);
    EXPECT_NEAR(r[1].t, float(std::sqrt(15.0)), 1e-5f);
    EXPECT_LT(r[1].object_normal.y, -0.9f);
    EXPECT_FLOAT_EQ(r[2].t, 7.5f);
    EXPECT_NEAR(r[2].object_normal.z, -1.0f, 1e-6f);
}

// Rays whose closest approach to the centre is r (1 ± 1e-3): a hit just inside, a miss just
// outside, and t as the double-precision answer to within a few float spacings.
TEST_F(SpheresTest, GrazingRaysAgreeWithTheDoublePrecisionReference) {
    const float3 c = make_float3(0.25f, -0.5f, 40.0f);
    const float radius = 3.0f;
    auto top = group_of(spheres({make_float4(c.x, c.y, c.z, radius)}), material(1));
    std::vector<SphereRay> rays;
    std::vector<bool> inside;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> angle(0.0f, 6.2831853f);
    for (int i = 0; i < 200; ++i) {
        const bool in = i % 2 == 0;
        const float miss_by = in ? 1.0f - 1e-3f : 1.0f + 1e-3f;
        const float a = angle(rng);
        const float3 offset =
            make_float3(std::cos(a), std::sin(a), 0.0f) * (radius * miss_by);
        rays.push_back(ray(make_float3(c.x + offset.x, c.y + offset.y, 0.0f),
                           make_float3(0, 0, 1)));
        inside.push_back(in);
    }
    auto r = cast(top, rays);
    for (size_t i = 0; i < rays.size(); ++i) {
        const ReferenceHit ref = reference_sphere(rays[i].origin, rays[i].direction, c, radius);
        ASSERT_EQ(ref.hit, bool(inside[i]));
        ASSERT_EQ(r[i].hit, inside[i] ? 1 : 0) << "ray " << i;
        if (inside[i]) EXPECT_NEAR(r[i].t, ref.t0, 2e-3 * radius) << "ray " << i;
    }
}

// A sphere of radius 1e-3 at distance 100 (r/distance = 1e-5): b² - ac in float, the
// textbook form, cancels to noise there; the closest-approach form keeps the answer.
TEST_F(SpheresTest, ThinDistantSpheresKeepTheirHitsAndDistances) {
    const float3 c = make_float3(3.0f, -2.0f, 100.0f);
    const float radius = 1e-3f;
    auto top = group_of(spheres({make_float4(c.x, c.y, c.z, radius)}), material(1));
    std::vector<SphereRay> rays;
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    const float3 origin = make_float3(0.1f, 0.2f, -0.3f);
    for (int i = 0; i < 400; ++i) {
        // Aim at a point within 1.5 r of the centre, across the disc facing the ray.
        const float3 target = c + make_float3(u(rng), u(rng), u(rng)) * (1.5f * radius);
        rays.push_back(ray(origin, target - origin));
    }
    auto r = cast(top, rays);
    int hits = 0, checked = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        const ReferenceHit ref = reference_sphere(rays[i].origin, rays[i].direction, c, radius);
        // The answer of a ray within 2 % of grazing may go either way in float.
        const ReferenceHit inner =
            reference_sphere(rays[i].origin, rays[i].direction, c, radius * 0.98f);
        const ReferenceHit outer =
            reference_sphere(rays[i].origin, rays[i].direction, c, radius * 1.02f);
        if (inner.hit != outer.hit) continue;
        ++checked;
        ASSERT_EQ(r[i].hit, ref.hit ? 1 : 0) << "ray " << i;
        if (!ref.hit) continue;
        ++hits;
        // t: the distance, to 1e-6 of itself (a few float spacings at 100).
        EXPECT_NEAR(r[i].t, ref.t0, 1e-6 * ref.t0) << "ray " << i;
        const double len = std::sqrt(double(dot(rays[i].direction, rays[i].direction)));
        EXPECT_NEAR(r[i].t * len, ref.t0 * len, 2e-4) << "ray " << i;
    }
    EXPECT_GT(checked, 300);
    EXPECT_GT(hits, 50);
}

TEST_F(SpheresTest, AnyHitSeesBothSidesAndIgnoringTheNearOneGivesTheFar) {
    auto both = group_of(spheres({make_float4(0, 0, 10, 2)}), material(1, true, true));
    auto r = cast(both, {ray(make_float3(0, 0, 0), make_float3(0, 0, 1))});
    EXPECT_EQ(r[0].hit, 0);
    EXPECT_EQ(r[0].anyhit_count, 2u);
    EXPECT_FLOAT_EQ(r[0].anyhit_t[0], 8.0f);
    EXPECT_FLOAT_EQ(r[0].anyhit_t[1], 12.0f);

    auto accept = group_of(spheres({make_float4(0, 0, 10, 2)}), material(1, true, false));
    r = cast(accept, {ray(make_float3(0, 0, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(r[0].hit, 1);
    EXPECT_EQ(r[0].anyhit_count, 1u);  // the near side accepted: the far one is beyond it
    EXPECT_FLOAT_EQ(r[0].t, 8.0f);
}

TEST_F(SpheresTest, TheRayIntervalSelectsTheSide) {
    auto top = group_of(spheres({make_float4(0, 0, 10, 2)}), material(1));
    auto r = cast(top, {ray(make_float3(0, 0, 0), make_float3(0, 0, 1), 9.0f),
                        ray(make_float3(0, 0, 0), make_float3(0, 0, 1), 0.0f, 7.9f),
                        ray(make_float3(0, 0, 0), make_float3(0, 0, 1), 12.5f)});
    ASSERT_EQ(r[0].hit, 1);
    EXPECT_FLOAT_EQ(r[0].t, 12.0f);
    EXPECT_EQ(r[0].entering, 0u);
    EXPECT_EQ(r[1].hit, 0);
    EXPECT_EQ(r[2].hit, 0);
}

TEST_F(SpheresTest, TransformsMoveAndScaleSpheresAndTheirNormals) {
    auto sphere_group = group_of(spheres({make_float4(0, 0, 0, 1)}), material(3));
    auto transform = ctx.create_transform();
    Matrix4x3 m = scaling(2, 2, 2);
    m.m[11] = 10.0f;  // then moved to z = 10
    transform->set_matrix(m);
    transform->set_child(sphere_group);
    auto top = ctx.create_group();
    top->add_child(transform);
    auto r = cast(top, {ray(make_float3(0, 0, 0), make_float3(0, 0, 1)),
                        ray(make_float3(0, 1.9f, 0), make_float3(0, 0, 1)),
                        ray(make_float3(0, 2.1f, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(r[0].hit, 1);
    EXPECT_FLOAT_EQ(r[0].t, 8.0f);
    EXPECT_NEAR(r[0].world_normal.z, -1.0f, 1e-6f);
    ASSERT_EQ(r[1].hit, 1);
    EXPECT_GT(r[1].world_normal.y, 0.9f);
    EXPECT_EQ(r[2].hit, 0);
}

TEST_F(SpheresTest, SpheresAndTrianglesShareAGroupAndTheNearestWins) {
    auto ball = make_instance(ctx, spheres({make_float4(0, 0, 10, 1)}), material(1));
    auto wall = make_instance(
        ctx, make_triangles(ctx, square_at(5.0f, -10, 10, 2, 10)),
        make_material(ctx, program(ctx, LUCENT_PROGRAM(sphere_test_triangle_hit)), 2));
    auto top = make_geometry_group(ctx, {ball, wall});
    auto r = cast(top, {ray(make_float3(0, 0, 0), make_float3(0, 0, 1)),
                        ray(make_float3(0, 3, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(r[0].hit, 1);
    EXPECT_EQ(r[0].id, 1u);
    EXPECT_FLOAT_EQ(r[0].t, 9.0f);
    ASSERT_EQ(r[1].hit, 1);
    EXPECT_EQ(r[1].id, 2u);
    EXPECT_FLOAT_EQ(r[1].t, 5.0f);
}

TEST_F(SpheresTest, OcclusionAndOpacityCullsTreatSpheresAsPrimitives) {
    auto g = spheres({make_float4(0, 0, 10, 1)});
    g->set_flags(kGeometryFlagDisableAnyHit);
    auto top = group_of(g, material(1, true, true));
    auto r = cast(top, {ray(make_float3(0, 0, 0), make_float3(0, 0, 1), 0, kInfinity,
                            kRayFlagNone, /*occlusion=*/1),
                        ray(make_float3(0, 0, 0), make_float3(0, 0, 1), 0, 5.0f, kRayFlagNone,
                            1),
                        ray(make_float3(0, 0, 0), make_float3(0, 0, 1)),
                        ray(make_float3(0, 0, 0), make_float3(0, 0, 1), 0, kInfinity,
                            kRayFlagCullDisabledAnyHit)});
    EXPECT_EQ(r[0].occluded, 1u);
    EXPECT_EQ(r[1].occluded, 0u);
    ASSERT_EQ(r[2].hit, 1);  // opaque: the ignoring any-hit never runs
    EXPECT_EQ(r[2].anyhit_count, 0u);
    EXPECT_EQ(r[3].hit, 0);  // opaque primitives culled
}

TEST_F(SpheresTest, OneRadiusServesEverySphereAndMaterialIndicesSelect) {
    auto g = ctx.create_geometry_spheres();
    g->set_centers(input_buffer(ctx, std::vector<float3>{make_float3(0, 0, 10),
                                                         make_float3(4, 0, 10)}));
    g->set_radii(input_buffer(ctx, std::vector<float>{0.5f}));
    g->set_material_indices(input_buffer(ctx, std::vector<unsigned>{1, 0}));
    auto inst = ctx.create_geometry_instance();
    inst->set_geometry(g);
    inst->add_material(material(10));
    inst->add_material(material(11));
    auto top = make_geometry_group(ctx, {inst});
    auto r = cast(top, {ray(make_float3(0, 0, 0), make_float3(0, 0, 1)),
                        ray(make_float3(4, 0, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(r[0].hit, 1);
    EXPECT_EQ(r[0].id, 11u);
    EXPECT_FLOAT_EQ(r[0].t, 9.5f);
    ASSERT_EQ(r[1].hit, 1);
    EXPECT_EQ(r[1].id, 10u);
    EXPECT_FLOAT_EQ(r[1].t, 9.5f);
}

// A field of overlapping spheres through the BVH: each ray's nearest sphere and distance
// as a brute-force double-precision search over all of them finds.
TEST_F(SpheresTest, AFieldOfSpheresGivesEachRayItsNearest) {
    std::vector<float4> field;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-10.0f, 10.0f), radius(0.2f, 1.5f);
    for (int i = 0; i < 300; ++i)
        field.push_back(make_float4(u(rng), u(rng), 20 + u(rng), radius(rng)));
    std::vector<SphereRay> rays;
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x)
            rays.push_back(ray(make_float3(0, 0, 0),
                               make_float3((x - 15.5f) / 30.0f, (y - 15.5f) / 30.0f, 1.0f)));
    auto built_in = cast(group_of(spheres(field), material(1)), rays);
    int hits = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        double best = INFINITY;
        unsigned best_prim = ~0u;
        for (size_t s = 0; s < field.size(); ++s) {
            const ReferenceHit h =
                reference_sphere(rays[i].origin, rays[i].direction,
                                 make_float3(field[s].x, field[s].y, field[s].z), field[s].w);
            if (h.hit && h.t0 > 0 && h.t0 < best) {
                best = h.t0;
                best_prim = unsigned(s);
            }
        }
        ASSERT_EQ(built_in[i].hit, best_prim != ~0u ? 1 : 0) << "ray " << i;
        if (best_prim == ~0u) continue;
        ++hits;
        EXPECT_EQ(built_in[i].prim, best_prim) << "ray " << i;
        EXPECT_NEAR(built_in[i].t, best, 1e-5 * best) << "ray " << i;
    }
    EXPECT_GT(hits, 100);
}

TEST_F(SpheresTest, MisuseIsRefusedNamingTheFix) {
    auto launch_with = [&](std::shared_ptr<GeometrySpheres> g, std::string word) {
        expect_error(
            [&] { cast(group_of(g, material(1)), {ray(make_float3(0, 0, 0), make_float3(0, 0, 1))}); },
            {"GeometrySpheres", word}, word.c_str());
    };
    launch_with(ctx.create_geometry_spheres(), "set_centers");
    auto no_radii = ctx.create_geometry_spheres();
    no_radii->set_centers(input_buffer(ctx, std::vector<float3>{make_float3(0, 0, 1)}));
    launch_with(no_radii, "set_radii");
    auto counts = ctx.create_geometry_spheres();
    counts->set_centers(input_buffer(ctx, std::vector<float3>(3, make_float3(0, 0, 1))));
    counts->set_radii(input_buffer(ctx, std::vector<float>{1, 2}));
    launch_with(counts, "one per sphere");
    launch_with(spheres({make_float4(0, 0, 5, -1)}), "at least 0");
    launch_with(spheres({make_float4(NAN, 0, 5, 1)}), "not finite");
    auto bad_material = spheres({make_float4(0, 0, 5, 1)});
    bad_material->set_material_indices(input_buffer(ctx, std::vector<unsigned>{2}));
    launch_with(bad_material, "selects material 2");
    auto g = ctx.create_geometry_spheres();
    expect_error([&] { g->set_centers(input_buffer(ctx, std::vector<float4>{})); }, {"float3"});
    expect_error([&] { g->set_radii(input_buffer(ctx, std::vector<float3>{})); },
                 {"buffer of float"});
    // A closest hit that reads another attribute type is refused, naming both types.
    auto wrong = make_instance(
        ctx, spheres({make_float4(0, 0, 5, 1)}),
        make_material(ctx, program(ctx, LUCENT_PROGRAM(sphere_test_triangle_hit)), 1));
    expect_error(
        [&] {
            cast(make_geometry_group(ctx, {wrong}),
                 {ray(make_float3(0, 0, 0), make_float3(0, 0, 1))});
        },
        {"BuiltinSphereAttributes", "TriangleAttributes"});
}

}  // namespace

// Built-in curves (GeometryCurves, OptiX's round curves): straight tubes of every type
// against the cylinder's closed form, grazing rays, end caps, rays from inside, thin curves
// far away and random bent segments of every type against a double-precision reference of
// the swept sphere (written here from the bases' own polynomials, not from curve_bezier),
// any-hit on both sides, intervals, transforms, per-segment materials, occlusion, and every
// misuse refused with a message naming the fix. Each case runs on the suite's backend
// (LUCENT_TEST_BACKEND), so CPU and GPU are held alike.
#include <algorithm>
#include <cmath>
#include <random>

#include "tests/programs/curve_programs.h"
#include "tests/test_support.h"

namespace {

using namespace lucent;
using namespace lucent_tests;

/// A segment's centre and radius at u in double, from its basis functions.
void reference_point(unsigned type, const float4* p, double u, double out[4]) {
    double w[4] = {0, 0, 0, 0};
    const double s = 1 - u;
    if (type == kCurveLinear) {
        w[0] = s, w[1] = u;
    } else if (type == kCurveQuadraticBSpline) {
        w[0] = 0.5 * s * s, w[1] = 0.5 + u - u * u, w[2] = 0.5 * u * u;
    } else if (type == kCurveCubicBSpline) {
        w[0] = s * s * s / 6, w[1] = (3 * u * u * u - 6 * u * u + 4) / 6;
        w[2] = (-3 * u * u * u + 3 * u * u + 3 * u + 1) / 6, w[3] = u * u * u / 6;
    } else {  // Catmull-Rom
        w[0] = 0.5 * (-u * u * u + 2 * u * u - u), w[1] = 0.5 * (3 * u * u * u - 5 * u * u + 2);
        w[2] = 0.5 * (-3 * u * u * u + 4 * u * u + u), w[3] = 0.5 * (u * u * u - u * u);
    }
    for (int c = 0; c < 4; ++c) out[c] = 0;
    for (unsigned i = 0; i < curve_control_points(type); ++i) {
        out[0] += w[i] * p[i].x;
        out[1] += w[i] * p[i].y;
        out[2] += w[i] * p[i].z;
        out[3] += w[i] * p[i].w;
    }
}

/// The ray's first entry into the union of the segment's spheres (radii scaled by
/// `radius_scale`), in double: the smallest z - sqrt(r^2 - rho^2) over 20,000 samples of u,
/// refined by ternary search around the best. Infinity for a miss.
double reference_entry(unsigned type, const float4* p, float3 o, float3 d,
                       double radius_scale = 1.0) {
    const double len = std::sqrt(double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z);
    const double dir[3] = {d.x / len, d.y / len, d.z / len};
    const auto entry = [&](double u) {
        double c[4];
        reference_point(type, p, u, c);
        const double q[3] = {c[0] - o.x, c[1] - o.y, c[2] - o.z};
        const double z = q[0] * dir[0] + q[1] * dir[1] + q[2] * dir[2];
        const double x[3] = {q[0] - z * dir[0], q[1] - z * dir[1], q[2] - z * dir[2]};
        const double r = c[3] * radius_scale;
        const double disc = r * r - (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        return disc >= 0 ? z - std::sqrt(disc) : INFINITY;
    };
    constexpr int kSamples = 20000;
    double best = INFINITY;
    int best_i = -1;
    for (int i = 0; i <= kSamples; ++i) {
        const double s = entry(double(i) / kSamples);
        if (s < best) best = s, best_i = i;
    }
    if (best_i < 0) return INFINITY;
    double lo = std::max(0.0, (best_i - 1.0) / kSamples);
    double hi = std::min(1.0, (best_i + 1.0) / kSamples);
    for (int k = 0; k < 60; ++k) {
        const double a = lo + (hi - lo) / 3, b = hi - (hi - lo) / 3;
        (entry(a) < entry(b) ? hi : lo) = entry(a) < entry(b) ? b : a;
    }
    return std::min(best, entry(0.5 * (lo + hi))) / len;
}

class CurvesTest : public testing::Test {
  public:
    explicit CurvesTest(ContextOptions options = test_context_options()) : ctx(options) {
        ctx.set_entry_point_count(1);
        ctx.set_ray_type<CurvePayload>(0, "radiance");
        ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(curve_miss)));
        ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(curve_cast)));
    }

    /// Curves of one type from control points (position xyz, radius w) and segment starts.
    std::shared_ptr<GeometryCurves> curves(unsigned type, const std::vector<float4>& points,
                                           const std::vector<unsigned>& segments) {
        std::vector<float3> vertices;
        std::vector<float> radii;
        for (const float4& v : points) {
            vertices.push_back(make_float3(v.x, v.y, v.z));
            radii.push_back(v.w);
        }
        auto g = ctx.create_geometry_curves();
        g->set_curve_type(CurveType(type));
        g->set_vertices(input_buffer(ctx, vertices));
        g->set_radii(input_buffer(ctx, radii));
        g->set_segment_indices(input_buffer(ctx, segments));
        return g;
    }
    /// One segment of `type` whose centre runs straight from x = 0 to x = 1 on the x axis
    /// with u = x, and radius r throughout (evenly spaced collinear control points).
    std::shared_ptr<GeometryCurves> straight(unsigned type, float r) {
        std::vector<float4> points;
        if (type == kCurveLinear)
            points = {make_float4(0, 0, 0, r), make_float4(1, 0, 0, r)};
        else if (type == kCurveQuadraticBSpline)
            points = {make_float4(-0.5f, 0, 0, r), make_float4(0.5f, 0, 0, r),
                      make_float4(1.5f, 0, 0, r)};
        else
            points = {make_float4(-1, 0, 0, r), make_float4(0, 0, 0, r), make_float4(1, 0, 0, r),
                      make_float4(2, 0, 0, r)};
        return curves(type, points, {0});
    }
    std::shared_ptr<Material> material(unsigned id, bool any_hit = false, bool ignore = false) {
        auto m = make_material(ctx, program(ctx, LUCENT_PROGRAM(curve_hit)), id);
        if (any_hit) {
            m->set_any_hit(0, program(ctx, LUCENT_PROGRAM(curve_any_hit)));
            (*m)["ignore"] = ignore ? 1u : 0u;
        }
        return m;
    }
    std::shared_ptr<GeometryGroup> group_of(std::shared_ptr<GeometryBase> g,
                                            std::shared_ptr<Material> m) {
        return make_geometry_group(ctx, {make_instance(ctx, std::move(g), std::move(m))});
    }

    std::vector<CurvePayload> cast(std::shared_ptr<Node> top, const std::vector<CurveRay>& rays) {
        auto results = ctx.create_buffer<CurvePayload>(BufferType::kOutput, unsigned(rays.size()));
        auto gen = ctx.ray_generation_program(0);
        (*gen)["top"] = top;
        (*gen)["rays"] = input_buffer(ctx, rays);
        (*gen)["results"] = results;
        ctx.launch(0, unsigned(rays.size()));
        EXPECT_EQ(ctx.last_launch().exception_count(), 0u) << ctx.last_launch().summary();
        return read_buffer<CurvePayload>(*results);
    }
    static CurveRay ray(float3 o, float3 d, float tmin = 0.0f, float tmax = kInfinity,
                        unsigned occlusion = 0) {
        return CurveRay{o, d, tmin, tmax, occlusion};
    }

    Context ctx;
};

const unsigned kEveryType[] = {kCurveLinear, kCurveQuadraticBSpline, kCurveCubicBSpline,
                               kCurveCatmullRom};

TEST_F(CurvesTest, StraightTubesOfEveryTypeAreTheCylinder) {
    const float r = 0.5f;
    for (unsigned type : kEveryType) {
        auto top = group_of(straight(type, r), material(4));
        std::vector<CurveRay> rays;
        for (int i = 0; i < 20; ++i) {
            const float x = 0.05f + 0.9f * i / 19.0f, y = -0.45f + 0.9f * ((i * 7) % 20) / 19.0f;
            rays.push_back(ray(make_float3(x, y, -5), make_float3(0, 0, 1)));
        }
        rays.push_back(ray(make_float3(0.5f, 0.6f, -5), make_float3(0, 0, 1)));  // beside it
        auto hits = cast(top, rays);
        for (size_t i = 0; i + 1 < rays.size(); ++i) {
            const float x = rays[i].origin.x, y = rays[i].origin.y;
            const float depth = std::sqrt(r * r - y * y);
            ASSERT_EQ(hits[i].hit, 1) << "type " << type << " ray " << i;
            EXPECT_EQ(hits[i].id, 4u);
            EXPECT_EQ(hits[i].prim, 0u);
            EXPECT_NEAR(hits[i].t, 5.0f - depth, 2e-5f) << "type " << type << " ray " << i;
            EXPECT_NEAR(hits[i].u, x, 2e-4f) << "type " << type << " ray " << i;
            EXPECT_NEAR(hits[i].object_normal.x, 0.0f, 2e-4f);
            EXPECT_NEAR(hits[i].object_normal.y, y / r, 2e-4f);
            EXPECT_NEAR(hits[i].object_normal.z, -depth / r, 2e-4f);
            EXPECT_EQ(hits[i].entering, 1u);
        }
        EXPECT_EQ(hits.back().hit, 0) << "type " << type;
    }
}

// Rays whose closest approach to the tube's axis is r (1 ± 1e-3): a hit just inside, a miss
// just outside.
TEST_F(CurvesTest, GrazingRaysAreHitsOrMissesAsTheyShouldBe) {
    const float r = 0.25f;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> along(0.1f, 0.9f), angle(0.0f, 6.2831853f);
    for (unsigned type : kEveryType) {
        auto top = group_of(straight(type, r), material(1));
        std::vector<CurveRay> rays;
        for (int i = 0; i < 100; ++i) {
            const float a = angle(rng), miss_by = i % 2 == 0 ? 1.0f - 1e-3f : 1.0f + 1e-3f;
            // Along the tangent direction (cos a, sin a) in the y-z plane, offset across it.
            const float3 dir = make_float3(0, std::cos(a), std::sin(a));
            const float3 across = make_float3(0, -std::sin(a), std::cos(a)) * (r * miss_by);
            rays.push_back(ray(make_float3(along(rng), 0, 0) + across - 3.0f * dir, dir));
        }
        auto hits = cast(top, rays);
        for (size_t i = 0; i < rays.size(); ++i) {
            ASSERT_EQ(hits[i].hit, i % 2 == 0 ? 1 : 0) << "type " << type << " ray " << i;
            const float m = 1.0f - 1e-3f;
            if (i % 2 == 0) EXPECT_NEAR(hits[i].t, 3.0f - r * std::sqrt(1.0f - m * m), 5e-3f * r);
        }
    }
}

TEST_F(CurvesTest, EndsAreRoundCapsAndRaysFromInsideLeave) {
    for (unsigned type : kEveryType) {
        auto top = group_of(straight(type, 0.5f), material(1));
        auto hits = cast(top, {ray(make_float3(5, 0, 0), make_float3(-1, 0, 0)),
                               ray(make_float3(-5, 0.3f, 0), make_float3(1, 0, 0)),
                               ray(make_float3(0.5f, 0, 0), make_float3(0, 0, 1)),
                               ray(make_float3(0.25f, 0.1f, 0), make_float3(0, -2, 0))});
        ASSERT_EQ(hits[0].hit, 1) << "type " << type;
        EXPECT_NEAR(hits[0].t, 3.5f, 1e-5f);  // the sphere at u = 1
        EXPECT_NEAR(hits[0].u, 1.0f, 1e-6f);
        EXPECT_NEAR(hits[0].object_normal.x, 1.0f, 1e-5f);
        ASSERT_EQ(hits[1].hit, 1);
        EXPECT_NEAR(hits[1].t, 5.0f - std::sqrt(0.25f - 0.09f), 1e-5f);  // the sphere at u = 0
        EXPECT_NEAR(hits[1].u, 0.0f, 1e-6f);
        ASSERT_EQ(hits[2].hit, 1);
        EXPECT_EQ(hits[2].entering, 0u);
        EXPECT_NEAR(hits[2].t, 0.5f, 1e-5f);
        EXPECT_NEAR(hits[2].object_normal.z, 1.0f, 1e-5f);
        EXPECT_NEAR(hits[2].u, 0.5f, 1e-4f);
        ASSERT_EQ(hits[3].hit, 1);
        EXPECT_EQ(hits[3].entering, 0u);
        EXPECT_NEAR(hits[3].t, 0.3f, 1e-5f);  // from y = 0.1 down to y = -0.5 at speed 2
        EXPECT_NEAR(hits[3].object_normal.y, -1.0f, 1e-5f);
    }
}

/// Random bent segments of every type, and rays aimed near points of them, against the
/// double-precision swept sphere: hit or miss (rays within 2 % of grazing excluded), the
/// distance, and the attributes' consistency (the hit lies on the sphere at u, the normal
/// points from its centre through the hit).
void expect_agrees_with_reference(CurvesTest& test, unsigned type, float radius_lo,
                                  float radius_hi, float distance, uint32_t seed,
                                  double t_tolerance);

TEST_F(CurvesTest, BentSegmentsOfEveryTypeAgreeWithTheDoublePrecisionReference) {
    for (unsigned type : kEveryType) expect_agrees_with_reference(*this, type, 0.03f, 0.15f, 4.0f, 17 + type, 2e-5);
}

// Radius 1e-3 seen from 100 (r / distance = 1e-5): the ray-centric coordinates keep the
// closest approach precise where |c - o|^2 - z^2 would cancel to noise.
TEST_F(CurvesTest, ThinCurvesFarAwayKeepTheirHitsAndDistances) {
    for (unsigned type : {unsigned(kCurveLinear), unsigned(kCurveCubicBSpline)})
        expect_agrees_with_reference(*this, type, 1e-3f, 1e-3f, 100.0f, 5 + type, 1e-6);
}

void expect_agrees_with_reference(CurvesTest& test, unsigned type, float radius_lo,
                                  float radius_hi, float distance, uint32_t seed,
                                  double t_tolerance) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), radius(radius_lo, radius_hi);
    const float scale = radius_hi > 0.01f ? 1.0f : 0.01f;  // thin curves are short too
    std::vector<float4> points;
    std::vector<unsigned> segments;
    const unsigned n = curve_control_points(type);
    constexpr int kSegments = 40;
    for (int s = 0; s < kSegments; ++s) {
        segments.push_back(unsigned(points.size()));
        for (unsigned i = 0; i < n; ++i)
            points.push_back(make_float4(unit(rng) * scale, unit(rng) * scale,
                                         distance + unit(rng) * scale, radius(rng)));
    }
    int checked = 0, hit_count = 0;
    for (int s = 0; s < kSegments; ++s) {
        // One segment per launch, so the reference is one segment's.
        const float4* p = &points[segments[s]];
        std::vector<float4> own(p, p + n);
        auto top = test.group_of(test.curves(type, own, {0}), test.material(1));
        std::vector<CurveRay> rays;
        const float3 origin = make_float3(0.1f, -0.2f, 0.05f);
        for (int i = 0; i < 12; ++i) {
            double c[4];
            reference_point(type, own.data(), (unit(rng) + 1) * 0.5, c);
            const float spread = 1.5f * float(c[3]);
            const float3 target = make_float3(float(c[0]) + unit(rng) * spread,
                                              float(c[1]) + unit(rng) * spread, float(c[2]));
            rays.push_back(CurvesTest::ray(origin, target - origin));
        }
        auto hits = test.cast(top, rays);
        for (size_t i = 0; i < rays.size(); ++i) {
            const float3 o = rays[i].origin, d = rays[i].direction;
            const double t = reference_entry(type, own.data(), o, d);
            if (std::isinf(reference_entry(type, own.data(), o, d, 0.98)) !=
                std::isinf(reference_entry(type, own.data(), o, d, 1.02)))
                continue;  // within 2 % of grazing: float may go either way
            ++checked;
            ASSERT_EQ(hits[i].hit, std::isinf(t) ? 0 : 1)
                << "type " << type << " segment " << s << " ray " << i;
            if (std::isinf(t)) continue;
            ++hit_count;
            EXPECT_NEAR(hits[i].t, t, t_tolerance * t) << "type " << type << " segment " << s;
            EXPECT_EQ(hits[i].entering, 1u);
            // The hit is on the sphere at u, and the normal points from its centre.
            double c[4];
            reference_point(type, own.data(), hits[i].u, c);
            const double hit[3] = {o.x + double(hits[i].t) * d.x, o.y + double(hits[i].t) * d.y,
                                   o.z + double(hits[i].t) * d.z};
            const double off[3] = {hit[0] - c[0], hit[1] - c[1], hit[2] - c[2]};
            const double dist = std::sqrt(off[0] * off[0] + off[1] * off[1] + off[2] * off[2]);
            EXPECT_NEAR(dist, c[3], 2e-3 * c[3] + 2e-6 * distance)
                << "type " << type << " segment " << s << " ray " << i;
            const double along = (off[0] * hits[i].object_normal.x +
                                  off[1] * hits[i].object_normal.y +
                                  off[2] * hits[i].object_normal.z) /
                                 dist;
            EXPECT_GT(along, 0.999) << "type " << type << " segment " << s << " ray " << i;
        }
    }
    EXPECT_GT(checked, kSegments * 8);
    EXPECT_GT(hit_count, kSegments * 3);
}

TEST_F(CurvesTest, AnyHitSeesEntryAndExitAndIntervalsSelectTheSide) {
    auto both = group_of(straight(kCurveCubicBSpline, 0.5f), material(1, true, true));
    auto hits = cast(both, {ray(make_float3(0.5f, 0, -5), make_float3(0, 0, 1))});
    EXPECT_EQ(hits[0].hit, 0);
    EXPECT_EQ(hits[0].anyhit_count, 2u);
    EXPECT_NEAR(hits[0].anyhit_t[0], 4.5f, 1e-5f);
    EXPECT_NEAR(hits[0].anyhit_t[1], 5.5f, 1e-5f);

    auto top = group_of(straight(kCurveCubicBSpline, 0.5f), material(1));
    hits = cast(top, {ray(make_float3(0.5f, 0, -5), make_float3(0, 0, 1), 4.6f),
                      ray(make_float3(0.5f, 0, -5), make_float3(0, 0, 1), 0.0f, 4.4f),
                      ray(make_float3(0.5f, 0, -5), make_float3(0, 0, 1), 5.6f)});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_NEAR(hits[0].t, 5.5f, 1e-5f);
    EXPECT_EQ(hits[0].entering, 0u);
    EXPECT_EQ(hits[1].hit, 0);
    EXPECT_EQ(hits[2].hit, 0);
}

TEST_F(CurvesTest, TransformsMoveAndScaleCurvesAndTheirNormals) {
    auto transform = ctx.create_transform();
    Matrix4x3 m = scaling(2, 2, 2);
    m.m[11] = 10.0f;  // then moved to z = 10
    transform->set_matrix(m);
    transform->set_child(group_of(straight(kCurveLinear, 0.5f), material(3)));
    auto top = ctx.create_group();
    top->add_child(transform);
    auto hits = cast(top, {ray(make_float3(1, 0, 0), make_float3(0, 0, 1)),
                           ray(make_float3(1, 0.9f, 0), make_float3(0, 0, 1)),
                           ray(make_float3(1, 1.1f, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_NEAR(hits[0].t, 9.0f, 1e-5f);
    EXPECT_NEAR(hits[0].u, 0.5f, 1e-4f);
    EXPECT_NEAR(hits[0].world_normal.z, -1.0f, 1e-5f);
    ASSERT_EQ(hits[1].hit, 1);
    EXPECT_GT(hits[1].world_normal.y, 0.8f);
    EXPECT_EQ(hits[2].hit, 0);
}

TEST_F(CurvesTest, PolylinesMaterialIndicesOcclusionAndMixedGroups) {
    // Three linear segments sharing vertices, along x from 0 to 3; segment 1 uses material 1.
    auto polyline = curves(kCurveLinear,
                           {make_float4(0, 0, 0, 0.2f), make_float4(1, 0, 0, 0.3f),
                            make_float4(2, 0, 0, 0.3f), make_float4(3, 0, 0, 0.2f)},
                           {0, 1, 2});
    polyline->set_material_indices(input_buffer(ctx, std::vector<unsigned>{0, 1, 0}));
    auto instance = ctx.create_geometry_instance();
    instance->set_geometry(polyline);
    instance->add_material(material(10));
    instance->add_material(material(11));
    auto ball = make_instance(ctx, [&] {
        auto s = ctx.create_geometry_spheres();
        s->set_centers(input_buffer(ctx, std::vector<float3>{make_float3(2.5f, 0, -1)}));
        s->set_radii(input_buffer(ctx, std::vector<float>{0.25f}));
        return s;
    }(), make_material(ctx, program(ctx, LUCENT_PROGRAM(curve_test_sphere_hit)), 20));
    auto top = make_geometry_group(ctx, {instance, ball});
    auto hits = cast(top, {ray(make_float3(0.5f, 0, -5), make_float3(0, 0, 1)),
                           ray(make_float3(1.5f, 0, -5), make_float3(0, 0, 1)),
                           ray(make_float3(1.0f, 0, -5), make_float3(0, 0, 1)),
                           ray(make_float3(2.5f, 0, -5), make_float3(0, 0, 1)),
                           ray(make_float3(1.5f, 0, -5), make_float3(0, 0, 1), 0, kInfinity, 1),
                           ray(make_float3(1.5f, 2, -5), make_float3(0, 0, 1), 0, kInfinity, 1)});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].id, 10u);
    EXPECT_EQ(hits[0].prim, 0u);
    // Above x = 0.5 the cone from radius 0.2 to 0.3 is the sphere at u = 0.52525 (where
    // u - 0.5 = r r'): height sqrt(0.252525^2 - 0.025253^2) = 0.251259.
    EXPECT_NEAR(hits[0].t, 5.0f - 0.251259f, 2e-5f);
    ASSERT_EQ(hits[1].hit, 1);
    EXPECT_EQ(hits[1].id, 11u);
    EXPECT_EQ(hits[1].prim, 1u);
    EXPECT_NEAR(hits[1].t, 4.7f, 1e-5f);
    ASSERT_EQ(hits[2].hit, 1);  // the joint: the sphere both segments share
    EXPECT_NEAR(hits[2].t, 4.7f, 1e-5f);
    ASSERT_EQ(hits[3].hit, 1);
    EXPECT_EQ(hits[3].id, 20u);  // the sphere in front of the curve
    EXPECT_EQ(hits[4].occluded, 1u);
    EXPECT_EQ(hits[5].occluded, 0u);
}

TEST_F(CurvesTest, MisuseIsRefusedNamingTheFix) {
    auto launch_with = [&](std::shared_ptr<GeometryCurves> g, std::string word) {
        expect_error(
            [&] { cast(group_of(g, material(1)), {ray(make_float3(0, 0, 0), make_float3(0, 0, 1))}); },
            {"GeometryCurves", word}, word.c_str());
    };
    launch_with(ctx.create_geometry_curves(), "set_vertices");
    auto no_radii = ctx.create_geometry_curves();
    no_radii->set_vertices(input_buffer(ctx, std::vector<float3>(4, make_float3(0, 0, 1))));
    launch_with(no_radii, "set_radii");
    auto no_segments = ctx.create_geometry_curves();
    no_segments->set_vertices(input_buffer(ctx, std::vector<float3>(4, make_float3(0, 0, 1))));
    no_segments->set_radii(input_buffer(ctx, std::vector<float>(4, 1.0f)));
    launch_with(no_segments, "set_segment_indices");
    auto counts = curves(kCurveLinear, {make_float4(0, 0, 1, 1), make_float4(1, 0, 1, 1)}, {0});
    counts->set_radii(input_buffer(ctx, std::vector<float>{1}));
    launch_with(counts, "one radius per vertex");
    launch_with(curves(kCurveCubicBSpline,
                       {make_float4(0, 0, 1, 1), make_float4(1, 0, 1, 1), make_float4(2, 0, 1, 1),
                        make_float4(3, 0, 1, 1)},
                       {0, 1}),
                "needs 4 control points");
    launch_with(curves(kCurveLinear, {make_float4(0, 0, 5, -1), make_float4(1, 0, 5, 1)}, {0}),
                "at least 0");
    launch_with(curves(kCurveLinear, {make_float4(NAN, 0, 5, 1), make_float4(1, 0, 5, 1)}, {0}),
                "not finite");
    auto bad_material = straight(kCurveLinear, 1);
    bad_material->set_material_indices(input_buffer(ctx, std::vector<unsigned>{2}));
    launch_with(bad_material, "selects material 2");
    auto g = ctx.create_geometry_curves();
    expect_error([&] { g->set_curve_type(CurveType(7)); }, {"curve type 7", "kCurveCatmullRom"});
    expect_error([&] { g->set_vertices(input_buffer(ctx, std::vector<float4>{})); }, {"float3"});
    expect_error([&] { g->set_radii(input_buffer(ctx, std::vector<float3>{})); },
                 {"buffer of float"});
    expect_error([&] { g->set_segment_indices(input_buffer(ctx, std::vector<uint3>{})); },
                 {"buffer of unsigned"});
    expect_error([&] { g->set_vertices(nullptr); }, {"null"});
    // A closest hit that reads another attribute type is refused, naming both types.
    auto wrong = make_instance(
        ctx, straight(kCurveLinear, 1),
        make_material(ctx, program(ctx, LUCENT_PROGRAM(curve_test_sphere_hit)), 1));
    expect_error(
        [&] {
            cast(make_geometry_group(ctx, {wrong}),
                 {ray(make_float3(0, 0, 0), make_float3(0, 0, 1))});
        },
        {"BuiltinCurveAttributes", "BuiltinSphereAttributes"});
}

/// The curves' scenes also compile as CUDA megakernels for sm_90 (no GPU needed): the CPU
/// suite proves the device code builds with NVRTC (the GPU suite launches it).
class CurvesJitTest : public CurvesTest {
  protected:
    static ContextOptions jit_options() {
        ContextOptions options = test_context_options();
#if LUCENT_HAVE_CUDA
        options.jit_check_sm = 90;  // a CPU-only build (the sanitized one) has no NVRTC
#endif
        return options;
    }
    CurvesJitTest() : CurvesTest(jit_options()) {}
};

TEST_F(CurvesJitTest, TheCurveScenesCompileAsMegakernelsForSm90) {
#if !LUCENT_HAVE_CUDA
    GTEST_SKIP() << "built without the CUDA toolkit: no megakernel to compile";
#else
    if (test_backend() != BackendKind::kCpu) GTEST_SKIP() << "the GPU compiles them to launch";
    auto top = group_of(straight(kCurveCatmullRom, 0.5f), material(2, true, false));
    auto hits = cast(top, {ray(make_float3(0.5f, 0, -5), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_NEAR(hits[0].t, 4.5f, 1e-5f);
#endif
}

}  // namespace

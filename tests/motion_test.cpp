// Motion blur (OptiX 7-9's semantics): ray_time() in every program that sees a ray, matrix
// and SRT motion transforms, moving built-in spheres and triangles, clamping and vanishing
// outside the time range, motion bounds in the BVHs above (checked against the analytic
// positions of many moving spheres), custom primitives that read ray_time(), and every
// misuse refused with a message naming the fix. Each case runs on the suite's backend
// (LUCENT_TEST_BACKEND) against the same analytic answers, so CPU and GPU are held alike.
#include <cmath>
#include <random>

#include "tests/programs/motion_programs.h"
#include "tests/test_support.h"

namespace {

using namespace lucent;
using namespace lucent_tests;

constexpr float kEps = 1e-4f;

/// A ray straight down -z from height 5 above (x, y), at `time`.
MotionRay down(float x, float y, float time, unsigned occlusion = 0) {
    return MotionRay{make_float3(x, y, 5.0f), make_float3(0, 0, -1), time, occlusion};
}

class MotionTest : public testing::Test {
  protected:
    explicit MotionTest(const ContextOptions& options = test_context_options()) : ctx(options) {
        ctx.set_entry_point_count(1);
        ctx.set_ray_type<MotionPayload>(0, "radiance");
        ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(motion_miss)));
        ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(motion_cast)));
    }

    std::shared_ptr<GeometrySpheres> spheres(const std::vector<float3>& centers, float radius) {
        auto g = ctx.create_geometry_spheres();
        g->set_centers(input_buffer(ctx, centers));
        g->set_radii(input_buffer(ctx, std::vector<float>{radius}));
        return g;
    }
    std::shared_ptr<GeometryGroup> sphere_group(std::shared_ptr<GeometryBase> g, unsigned id) {
        return make_geometry_group(
            ctx, {make_instance(
                     ctx, std::move(g),
                     make_material(ctx, program(ctx, LUCENT_PROGRAM(motion_sphere_hit)), id))});
    }
    std::shared_ptr<GeometryGroup> triangle_group(std::shared_ptr<GeometryBase> g, unsigned id) {
        return make_geometry_group(
            ctx, {make_instance(
                     ctx, std::move(g),
                     make_material(ctx, program(ctx, LUCENT_PROGRAM(motion_triangle_hit)), id))});
    }
    /// A Group holding `node` and, far away, a static sphere: the Group's BVH must bound
    /// the motion for `node` to be found.
    std::shared_ptr<Group> beside_static(std::shared_ptr<Node> node) {
        auto group = ctx.create_group();
        group->add_child(std::move(node));
        group->add_child(sphere_group(spheres({make_float3(50, 50, 0)}, 1.0f), 99));
        return group;
    }

    std::vector<MotionPayload> cast(std::shared_ptr<Node> top, const std::vector<MotionRay>& rays) {
        auto results = ctx.create_buffer<MotionPayload>(BufferType::kOutput, unsigned(rays.size()));
        auto gen = ctx.ray_generation_program(0);
        (*gen)["top"] = top;
        (*gen)["rays"] = input_buffer(ctx, rays);
        (*gen)["results"] = results;
        ctx.launch(0, unsigned(rays.size()));
        EXPECT_EQ(ctx.last_launch().exception_count(), 0u) << ctx.last_launch().summary();
        return read_buffer<MotionPayload>(*results);
    }

    Context ctx;
};

// ---- ray time -----------------------------------------------------------------------------

TEST_F(MotionTest, RayTimeReachesClosestHitAndMissAndIsZeroOutsideATrace) {
    auto top = sphere_group(spheres({make_float3(0, 0, 0)}, 1.0f), 1);
    const auto r = cast(top, {down(0, 0, 0.25f), down(5, 0, 0.75f), down(0, 0, -3.5f)});
    EXPECT_EQ(r[0].hit, 1);
    EXPECT_EQ(r[0].time, 0.25f);
    EXPECT_EQ(r[1].hit, 0);
    EXPECT_EQ(r[1].time, 0.75f);
    EXPECT_EQ(r[2].hit, 1);  // a static scene ignores the time
    EXPECT_EQ(r[2].time, -3.5f);
    for (const MotionPayload& p : r) EXPECT_EQ(p.generation_time, 0.0f);
}

TEST_F(MotionTest, CustomPrimitiveMovesByRayTimeInItsIntersectionProgram) {
    auto geometry = ctx.create_geometry();
    geometry->set_primitive_count(1);
    geometry->set_intersection_program(program(ctx, LUCENT_PROGRAM(timed_sphere_intersect)));
    geometry->set_bounding_box_program(program(ctx, LUCENT_PROGRAM(timed_sphere_bounds)));
    (*geometry)["center"] = make_float3(0, 0, 0);
    (*geometry)["velocity"] = make_float3(2, 0, 0);
    (*geometry)["radius"] = 0.5f;
    const auto r = cast(sphere_group(geometry, 3), {down(1, 0, 0.5f), down(1, 0, 0.0f)});
    EXPECT_EQ(r[0].hit, 1);
    EXPECT_NEAR(r[0].t, 4.5f, kEps);
    EXPECT_EQ(r[1].hit, 0);
}

// ---- matrix motion transforms ---------------------------------------------------------------

TEST_F(MotionTest, MatrixKeysMoveTheChildLinearlyAndClampOutsideTheRange) {
    // A sphere of radius 0.5 moving from x = 0 to x = 2 over [0, 1].
    auto t = ctx.create_transform();
    t->set_child(sphere_group(spheres({make_float3(0, 0, 0)}, 0.5f), 7));
    const std::vector<Matrix4x3> keys{translation(0, 0, 0), translation(2, 0, 0)};
    t->set_motion_matrices(keys);
    const auto r =
        cast(beside_static(t), {down(1, 0, 0.5f), down(1, 0, 0.0f), down(1, 0, 1.0f),
                                down(0, 0, 0.0f), down(2, 0, 1.0f), down(0, 0, -1.0f),
                                down(2, 0, 2.0f), down(0, 0, 0.5f), down(1.4f, 0, 0.5f)});
    EXPECT_EQ(r[0].hit, 1);
    EXPECT_EQ(r[0].id, 7u);
    EXPECT_NEAR(r[0].t, 4.5f, kEps);
    EXPECT_EQ(r[1].hit, 0);  // at time 0 the sphere is at x = 0
    EXPECT_EQ(r[2].hit, 0);  // and at x = 2 at time 1
    EXPECT_EQ(r[3].hit, 1);
    EXPECT_EQ(r[4].hit, 1);
    EXPECT_EQ(r[5].hit, 1);  // before the range: clamped to the first key
    EXPECT_EQ(r[6].hit, 1);  // after it: the last key
    EXPECT_EQ(r[7].hit, 0);
    // Off centre: the sphere at x = 1 seen 0.4 aside, t = 5 - sqrt(0.25 - 0.16).
    EXPECT_EQ(r[8].hit, 1);
    EXPECT_NEAR(r[8].t, 5.0f - std::sqrt(0.09f), kEps);
    // Its normal is the object-space one: the key interpolation gives x = 1, so (0.8, 0, 0.6).
    EXPECT_NEAR(r[8].normal.x, 0.8f, kEps);
    EXPECT_NEAR(r[8].normal.z, 0.6f, kEps);
}

TEST_F(MotionTest, VanishFlagsRemoveTheChildOutsideTheRange) {
    auto make = [&](unsigned flags) {
        auto t = ctx.create_transform();
        t->set_child(sphere_group(spheres({make_float3(0, 0, 0)}, 0.5f), 7));
        const std::vector<Matrix4x3> keys{translation(0, 0, 0), translation(2, 0, 0)};
        t->set_motion_matrices(keys, MotionOptions{0.0f, 1.0f, flags});
        return t;
    };
    const std::vector<MotionRay> rays{down(0, 0, -0.5f), down(0, 0, 0.0f), down(2, 0, 1.0f),
                                      down(2, 0, 1.5f)};
    const auto start = cast(make(kMotionFlagStartVanish), rays);
    EXPECT_EQ(start[0].hit, 0);
    EXPECT_EQ(start[1].hit, 1);  // the range's own ends are inside it
    EXPECT_EQ(start[2].hit, 1);
    EXPECT_EQ(start[3].hit, 1);
    const auto end = cast(make(kMotionFlagEndVanish), rays);
    EXPECT_EQ(end[0].hit, 1);
    EXPECT_EQ(end[1].hit, 1);
    EXPECT_EQ(end[2].hit, 1);
    EXPECT_EQ(end[3].hit, 0);
}

TEST_F(MotionTest, ThreeKeysAreSpacedEvenlyOverTheTimeRange) {
    // x = 0, 4, 0 at times 2, 3, 4: x = 2 at 2.5 and 3.5, x = 4 at 3.
    auto t = ctx.create_transform();
    t->set_child(sphere_group(spheres({make_float3(0, 0, 0)}, 0.5f), 7));
    const std::vector<Matrix4x3> keys{translation(0, 0, 0), translation(4, 0, 0),
                                      translation(0, 0, 0)};
    t->set_motion_matrices(keys, MotionOptions{2.0f, 4.0f});
    const auto r = cast(beside_static(t), {down(2, 0, 2.5f), down(2, 0, 3.5f), down(4, 0, 3.0f),
                                           down(2, 0, 3.0f), down(0, 0, 1.0f)});
    EXPECT_EQ(r[0].hit, 1);
    EXPECT_EQ(r[1].hit, 1);
    EXPECT_EQ(r[2].hit, 1);
    EXPECT_EQ(r[3].hit, 0);
    EXPECT_EQ(r[4].hit, 1);  // clamped to the first key
}

TEST_F(MotionTest, MotionTransformsNestUnderStaticOnes) {
    // Static: scale 2; inside it the motion from x = 0 to x = 1 (world 0 to 2).
    auto inner = ctx.create_transform();
    inner->set_child(sphere_group(spheres({make_float3(0, 0, 0)}, 0.25f), 7));
    const std::vector<Matrix4x3> keys{translation(0, 0, 0), translation(1, 0, 0)};
    inner->set_motion_matrices(keys);
    auto outer = ctx.create_transform();
    outer->set_matrix(scaling(2, 2, 2));
    outer->set_child(inner);
    const auto r = cast(beside_static(outer), {down(1, 0, 0.5f), down(1, 0, 0.0f)});
    EXPECT_EQ(r[0].hit, 1);
    EXPECT_NEAR(r[0].t, 4.5f, kEps);  // world radius 0.5
    EXPECT_EQ(r[1].hit, 0);
}

// ---- SRT motion transforms ------------------------------------------------------------------

SrtData srt(float scale, float3 translate, float4 quaternion, float3 pivot = make_float3(0.0f)) {
    SrtData d{};
    d.sx = d.sy = d.sz = scale;
    d.pvx = pivot.x, d.pvy = pivot.y, d.pvz = pivot.z;
    d.qx = quaternion.x, d.qy = quaternion.y, d.qz = quaternion.z, d.qw = quaternion.w;
    d.tx = translate.x, d.ty = translate.y, d.tz = translate.z;
    return d;
}

TEST_F(MotionTest, SrtRotationInterpolatesTheQuaternionByNlerp) {
    // A sphere at (1, 0, 0) rotated about z from 0 to 180 degrees: the normalised halfway
    // quaternion is 90 degrees, so at time 0.5 the sphere is at (0, 1, 0).
    auto t = ctx.create_transform();
    t->set_child(sphere_group(spheres({make_float3(1, 0, 0)}, 0.25f), 7));
    const std::vector<SrtData> keys{srt(1, make_float3(0.0f), make_float4(0, 0, 0, 1)),
                                    srt(1, make_float3(0.0f), make_float4(0, 0, 1, 0))};
    t->set_motion_srt(keys);
    const auto r = cast(beside_static(t), {down(0, 1, 0.5f), down(1, 0, 0.5f), down(1, 0, 0.0f),
                                           down(-1, 0, 1.0f), down(0, 1, 0.0f)});
    EXPECT_EQ(r[0].hit, 1);
    EXPECT_NEAR(r[0].t, 4.75f, kEps);
    EXPECT_EQ(r[1].hit, 0);
    EXPECT_EQ(r[2].hit, 1);
    EXPECT_EQ(r[3].hit, 1);
    EXPECT_EQ(r[4].hit, 0);
    // nlerp at time 0.25: q = normalise(0, 0, 0.25, 0.75), an angle of 2 atan(1/3).
    const float angle = 2.0f * std::atan(1.0f / 3.0f);
    const auto q = cast(beside_static(t), {down(std::cos(angle), std::sin(angle), 0.25f)});
    EXPECT_EQ(q[0].hit, 1);
    EXPECT_NEAR(q[0].t, 4.75f, 1e-3f);
}

TEST_F(MotionTest, SrtScalesAboutThePivotThenRotatesThenTranslates) {
    // S: scale 2 with pivot (1, 0, 0); R: 90 degrees about z; T: x from 0 to 4 over [0, 1].
    // The object point (1, 0, 0) goes to S: (3, 0, 0), R: (0, 3, 0), T at 0.5: (2, 3, 0).
    const float h = std::sqrt(0.5f);
    auto t = ctx.create_transform();
    t->set_child(sphere_group(spheres({make_float3(1, 0, 0)}, 0.25f), 7));
    const std::vector<SrtData> keys{
        srt(2, make_float3(0, 0, 0), make_float4(0, 0, h, h), make_float3(1, 0, 0)),
        srt(2, make_float3(4, 0, 0), make_float4(0, 0, h, h), make_float3(1, 0, 0))};
    t->set_motion_srt(keys);
    const auto r = cast(beside_static(t), {down(2, 3, 0.5f), down(4, 3, 1.0f), down(2, 3, 0.0f)});
    EXPECT_EQ(r[0].hit, 1);
    EXPECT_NEAR(r[0].t, 4.5f, kEps);  // world radius 0.5
    EXPECT_EQ(r[1].hit, 1);
    EXPECT_EQ(r[2].hit, 0);
}

// ---- moving primitives ---------------------------------------------------------------------

TEST_F(MotionTest, MovingSphereCentresInterpolateAtTheRayTime) {
    auto g = ctx.create_geometry_spheres();
    g->set_motion_centers({input_buffer(ctx, std::vector<float3>{make_float3(0, 0, 0)}),
                           input_buffer(ctx, std::vector<float3>{make_float3(2, 0, 0)})},
                          MotionOptions{0.0f, 1.0f, kMotionFlagEndVanish});
    g->set_radii(input_buffer(ctx, std::vector<float>{0.5f}));
    const auto r =
        cast(beside_static(sphere_group(g, 5)),
             {down(1, 0, 0.5f), down(1, 0, 0.0f), down(1.4f, 0, 0.5f), down(0, 0, -2.0f),
              down(2, 0, 1.0f), down(2, 0, 1.01f), down(1, 0, 0.5f, 1), down(1, 0, 0.0f, 1)});
    EXPECT_EQ(r[0].hit, 1);
    EXPECT_EQ(r[0].id, 5u);
    EXPECT_NEAR(r[0].t, 4.5f, kEps);
    EXPECT_EQ(r[1].hit, 0);
    EXPECT_EQ(r[2].hit, 1);
    EXPECT_NEAR(r[2].normal.x, 0.8f, kEps);
    EXPECT_NEAR(r[2].normal.z, 0.6f, kEps);
    EXPECT_EQ(r[3].hit, 1);  // clamped before the range
    EXPECT_EQ(r[4].hit, 1);
    EXPECT_EQ(r[5].hit, 0);  // vanished after it
    EXPECT_EQ(r[6].occluded, 1u);
    EXPECT_EQ(r[7].occluded, 0u);
}

TEST_F(MotionTest, MovingTrianglesInterpolateTheirVerticesAtTheRayTime) {
    // A square at z = 0 sinking to z = -2 over [0, 1], indexed, tilted at the last key.
    std::vector<float3> k0 = square_at(0.0f, -1, 1, -1, 1), k1 = square_at(-2.0f, -1, 1, -1, 1);
    auto g = ctx.create_geometry_triangles();
    g->set_motion_vertices({input_buffer(ctx, k0), input_buffer(ctx, k1)});
    const auto r = cast(beside_static(triangle_group(g, 4)),
                        {down(0.5f, 0.2f, 0.5f), down(-0.5f, 0.6f, 0.25f), down(0.5f, 0.2f, 3.0f),
                         down(3, 0, 0.5f), down(0.5f, 0.2f, 0.5f, 1)});
    EXPECT_EQ(r[0].hit, 1);
    EXPECT_EQ(r[0].id, 4u);
    EXPECT_NEAR(r[0].t, 6.0f, kEps);
    EXPECT_NEAR(std::fabs(normalize(r[0].normal).z), 1.0f, kEps);
    EXPECT_EQ(r[1].hit, 1);
    EXPECT_NEAR(r[1].t, 5.5f, kEps);
    EXPECT_EQ(r[2].hit, 1);  // clamped to the last key
    EXPECT_NEAR(r[2].t, 7.0f, kEps);
    EXPECT_EQ(r[3].hit, 0);
    EXPECT_EQ(r[4].occluded, 1u);
}

TEST_F(MotionTest, MovingTriangleNormalsFollowTheInterpolatedVertices) {
    // One triangle whose third vertex rises: at time 0.5 its plane has slope 1 in y.
    const std::vector<float3> k0{make_float3(-1, -1, 0), make_float3(1, -1, 0),
                                 make_float3(0, 1, 0)};
    const std::vector<float3> k1{make_float3(-1, -1, 0), make_float3(1, -1, 0),
                                 make_float3(0, 1, 4)};
    auto g = ctx.create_geometry_triangles();
    g->set_motion_vertices({input_buffer(ctx, k0), input_buffer(ctx, k1)});
    const auto r = cast(triangle_group(g, 4), {down(0, 0, 0.5f)});
    ASSERT_EQ(r[0].hit, 1);
    const float3 n = normalize(r[0].normal);
    // The edges (2, 0, 0) and (1, 2, 2): the normal is along (0, -4, 4).
    EXPECT_NEAR(n.x, 0.0f, kEps);
    EXPECT_NEAR(std::fabs(n.y), std::sqrt(0.5f), kEps);
    EXPECT_NEAR(std::fabs(n.z), std::sqrt(0.5f), kEps);
    EXPECT_NEAR(r[0].t, 5.0f - 1.0f, kEps);  // z = 1 at y = 0, time 0.5
}

TEST_F(MotionTest, ManyMovingSpheresAgreeWithTheirAnalyticPositions) {
    // 200 spheres moving in random directions over [0, 1] under a motion transform, hit
    // by random rays at random times: every answer matches the nearest sphere found by
    // brute force over the interpolated centres (the BVH's motion bounds lose none).
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-4.0f, 4.0f), time(-0.2f, 1.2f);
    std::vector<float3> k0, k1;
    for (int i = 0; i < 200; ++i) {
        k0.push_back(make_float3(u(rng), u(rng), u(rng) * 0.25f));
        k1.push_back(k0.back() + make_float3(u(rng), u(rng), 0.0f) * 0.5f);
    }
    const float radius = 0.3f;
    auto g = ctx.create_geometry_spheres();
    g->set_motion_centers({input_buffer(ctx, k0), input_buffer(ctx, k1)});
    g->set_radii(input_buffer(ctx, std::vector<float>{radius}));
    auto t = ctx.create_transform();
    t->set_child(sphere_group(g, 5));
    const std::vector<Matrix4x3> keys{translation(0, 0, 0), translation(0, 3, 0)};
    t->set_motion_matrices(keys);
    std::vector<MotionRay> rays;
    for (int i = 0; i < 2000; ++i)
        rays.push_back(down(u(rng) * 1.5f, u(rng) * 1.5f + 1.5f, time(rng)));
    const auto r = cast(beside_static(t), rays);
    int hits = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        const float s = std::min(std::max(rays[i].time, 0.0f), 1.0f);
        float best = kInfinity;
        unsigned prim = 0;
        for (unsigned p = 0; p < k0.size(); ++p) {
            const float3 c = k0[p] + s * (k1[p] - k0[p]) + make_float3(0, 3 * s, 0);
            const float dx = rays[i].origin.x - c.x, dy = rays[i].origin.y - c.y;
            const float d2 = radius * radius - dx * dx - dy * dy;
            if (d2 < 0) continue;
            const float tt = rays[i].origin.z - c.z - std::sqrt(d2);
            if (tt > 0 && tt < best) best = tt, prim = p;
        }
        if (best == kInfinity) {
            EXPECT_EQ(r[i].hit, 0) << "ray " << i;
            continue;
        }
        ++hits;
        ASSERT_EQ(r[i].hit, 1) << "ray " << i;
        EXPECT_EQ(r[i].prim, prim) << "ray " << i;
        EXPECT_NEAR(r[i].t, best, 1e-3f) << "ray " << i;
    }
    EXPECT_GT(hits, 200);
}

// ---- the megakernel -------------------------------------------------------------------------

/// The motion scenes also compile as CUDA megakernels for sm_90 (no GPU needed): the CPU
/// suite proves the device code builds with NVRTC (the GPU suite launches it).
class MotionJitTest : public MotionTest {
  protected:
    static ContextOptions jit_options() {
        ContextOptions options = test_context_options();
#if LUCENT_HAVE_CUDA
        options.jit_check_sm = 90;  // a CPU-only build (the sanitized one) has no NVRTC
#endif
        return options;
    }
    MotionJitTest() : MotionTest(jit_options()) {}
};

TEST_F(MotionJitTest, EveryKindOfMotionCompilesAsAMegakernelForSm90) {
#if !LUCENT_HAVE_CUDA
    GTEST_SKIP() << "built without the CUDA toolkit: no megakernel to compile";
#else
    if (test_backend() != BackendKind::kCpu) GTEST_SKIP() << "the GPU compiles them to launch";
    auto spheres = ctx.create_geometry_spheres();
    spheres->set_motion_centers({input_buffer(ctx, std::vector<float3>{make_float3(0, 0, 0)}),
                                 input_buffer(ctx, std::vector<float3>{make_float3(2, 0, 0)})});
    spheres->set_radii(input_buffer(ctx, std::vector<float>{0.5f}));
    auto triangles = ctx.create_geometry_triangles();
    triangles->set_motion_vertices(
        {input_buffer(ctx, square_at(-1.0f)), input_buffer(ctx, square_at(-2.0f))});
    auto srt_node = ctx.create_transform();
    srt_node->set_child(sphere_group(spheres, 1));
    const std::vector<SrtData> keys{srt(1, make_float3(0.0f), make_float4(0, 0, 0, 1)),
                                    srt(1, make_float3(1, 0, 0), make_float4(0, 0, 0, 1))};
    srt_node->set_motion_srt(keys);
    auto group = beside_static(srt_node);
    group->add_child(triangle_group(triangles, 2));
    const auto r = cast(group, {down(1.5f, 0, 0.5f), down(8, 0, 0.5f)});
    EXPECT_EQ(r[0].hit, 1);
    EXPECT_NEAR(r[0].t, 4.5f, kEps);
    EXPECT_EQ(r[1].hit, 1);
    EXPECT_EQ(r[1].id, 2u);
    EXPECT_NEAR(r[1].t, 6.5f, kEps);
#endif
}

// ---- misuse ---------------------------------------------------------------------------------

TEST_F(MotionTest, BadMotionKeysAndRangesAreRefusedWithTheFix) {
    auto t = ctx.create_transform();
    const std::vector<Matrix4x3> one{translation(0, 0, 0)};
    expect_error([&] { t->set_motion_matrices(one); }, {"at least 2 keys"});
    const std::vector<Matrix4x3> two{translation(0, 0, 0), translation(1, 0, 0)};
    expect_error(
        [&] {
            t->set_motion_matrices(two, MotionOptions{1.0f, 1.0f});
        },
        {"time_begin < time_end"});
    expect_error([&] { t->set_motion_matrices(two, MotionOptions{0.0f, NAN}); }, {"finite times"});
    expect_error(
        [&] {
            t->set_motion_matrices(two, MotionOptions{0.0f, 1.0f, 4u});
        },
        {"unknown flag"});
    const std::vector<Matrix4x3> nan{translation(0, 0, 0), translation(NAN, 0, 0)};
    expect_error([&] { t->set_motion_matrices(nan); }, {"non-finite"});
    const std::vector<SrtData> zero_q{srt(1, make_float3(0.0f), make_float4(0, 0, 0, 1)),
                                      srt(1, make_float3(0.0f), make_float4(0, 0, 0, 0))};
    expect_error([&] { t->set_motion_srt(zero_q); }, {"zero quaternion"});

    auto g = ctx.create_geometry_spheres();
    auto a = input_buffer(ctx, std::vector<float3>{make_float3(0.0f)});
    auto b = input_buffer(ctx, std::vector<float3>{make_float3(0.0f), make_float3(1.0f)});
    expect_error([&] { g->set_motion_centers({a}); }, {"at least 2 keys"});
    expect_error([&] { g->set_motion_centers({a, b}); }, {"same count"});
    expect_error([&] { g->set_motion_centers({a, nullptr}); }, {"is null"});
    auto floats = input_buffer(ctx, std::vector<float>{1.0f});
    auto tris = ctx.create_geometry_triangles();
    expect_error([&] { tris->set_motion_vertices({floats, floats}); }, {"float3"});
}

TEST_F(MotionTest, SingularKeysAndResizedKeyBuffersAreReportedAtLaunch) {
    auto t = ctx.create_transform();
    t->set_child(sphere_group(spheres({make_float3(0, 0, 0)}, 0.5f), 7));
    const std::vector<Matrix4x3> keys{translation(0, 0, 0), scaling(0, 1, 1)};
    t->set_motion_matrices(keys);
    auto gen = ctx.ray_generation_program(0);
    (*gen)["top"] = std::shared_ptr<Node>(t);
    (*gen)["rays"] = input_buffer(ctx, std::vector<MotionRay>{down(0, 0, 0)});
    (*gen)["results"] = ctx.create_buffer<MotionPayload>(BufferType::kOutput, 1);
    expect_error([&] { ctx.launch(0, 1); }, {"motion key 1 is singular"});

    auto g = ctx.create_geometry_spheres();
    auto k1 = input_buffer(ctx, std::vector<float3>{make_float3(1.0f)});
    g->set_motion_centers({input_buffer(ctx, std::vector<float3>{make_float3(0.0f)}), k1});
    g->set_radii(input_buffer(ctx, std::vector<float>{0.5f}));
    k1->resize(2);
    (*gen)["top"] = std::shared_ptr<Node>(sphere_group(g, 1));
    expect_error([&] { ctx.launch(0, 1); }, {"give every key the same count"});
}

TEST_F(MotionTest, SetMatrixAndSetCentersMakeTheObjectStaticAgain) {
    auto t = ctx.create_transform();
    t->set_child(sphere_group(spheres({make_float3(0, 0, 0)}, 0.5f), 7));
    const std::vector<Matrix4x3> keys{translation(0, 0, 0), translation(2, 0, 0)};
    t->set_motion_matrices(keys);
    EXPECT_EQ(t->motion(), TransformMotion::kMatrix);
    EXPECT_EQ(t->motion_key_count(), 2u);
    t->set_matrix(translation(5, 0, 0));
    EXPECT_EQ(t->motion(), TransformMotion::kNone);
    const auto r = cast(t, {down(5, 0, 0.5f), down(1, 0, 0.5f)});
    EXPECT_EQ(r[0].hit, 1);
    EXPECT_EQ(r[1].hit, 0);

    auto g = ctx.create_geometry_spheres();
    g->set_motion_centers({input_buffer(ctx, std::vector<float3>{make_float3(0, 0, 0)}),
                           input_buffer(ctx, std::vector<float3>{make_float3(2, 0, 0)})});
    g->set_radii(input_buffer(ctx, std::vector<float>{0.5f}));
    EXPECT_EQ(g->motion_buffers().size(), 2u);
    g->set_centers(input_buffer(ctx, std::vector<float3>{make_float3(3, 0, 0)}));
    EXPECT_TRUE(g->motion_buffers().empty());
    const auto s = cast(sphere_group(g, 1), {down(3, 0, 0.5f), down(1, 0, 0.5f)});
    EXPECT_EQ(s[0].hit, 1);
    EXPECT_EQ(s[1].hit, 0);
}

TEST_F(MotionTest, MovingGeometryRebuildsWhenAKeyBufferChanges) {
    // The BVH boxes the keys: new contents in a key buffer must rebuild it, or the sphere
    // would be culled where it now is.
    auto k1 = input_buffer(ctx, std::vector<float3>{make_float3(2, 0, 0)});
    auto g = ctx.create_geometry_spheres();
    g->set_motion_centers({input_buffer(ctx, std::vector<float3>{make_float3(0, 0, 0)}), k1});
    g->set_radii(input_buffer(ctx, std::vector<float>{0.5f}));
    auto top = beside_static(sphere_group(g, 1));
    EXPECT_EQ(cast(top, {down(1, 0, 0.5f)})[0].hit, 1);
    k1->upload(std::vector<float3>{make_float3(0, 6, 0)});
    const auto r = cast(top, {down(1, 0, 0.5f), down(0, 3, 0.5f), down(0, 6, 1.0f)});
    EXPECT_EQ(r[0].hit, 0);
    EXPECT_EQ(r[1].hit, 1);
    EXPECT_EQ(r[2].hit, 1);
}

}  // namespace

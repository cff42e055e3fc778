// Every program kind of the OptiX pipeline (paper §3.1) exercised on the CPU backend:
// ray generation over 1D/2D/3D grids, miss, intersection + closest hit (custom and
// built-in triangles), attribute programs, any hit (ignore/terminate), material
// selection, callables, recursion, print and textures.
#include "tests/programs/program_kinds.h"
#include "tests/test_support.h"

// gtest compares and prints through ADL, which looks in uint3's (global) namespace.
static bool operator==(uint3 a, uint3 b) {
    return a.x == b.x && a.y == b.y && a.z == b.z;
}
static std::ostream& operator<<(std::ostream& os, uint3 v) {
    return os << "(" << v.x << "," << v.y << "," << v.z << ")";
}

namespace lucent_tests {
namespace {

using testing::HasSubstr;
using testing::Not;

/// Sets an environment variable for one test's scope (the CUDA backend reads its tuning
/// switches when it compiles a scene's kernels, at the first launch).
class ScopedEnv {
  public:
    ScopedEnv(const char* name, const char* value) : m_name(name) { setenv(name, value, 1); }
    ~ScopedEnv() { unsetenv(m_name); }

  private:
    const char* m_name;
};

// ---- ray generation ------------------------------------------------------------

class RayGenerationTest : public testing::Test {
  protected:
    RayGenerationTest() : ctx(test_context_options()) { ctx.set_entry_point_count(1); }
    Context ctx;
};

TEST_F(RayGenerationTest, OneDimensionalLaunchSeesEveryIndexAndTheSize) {
    // 1037 is not a multiple of any tile size a backend might use.
    constexpr unsigned kWidth = 1037;
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(pk_write_index_1d)));
    auto output = ctx.create_buffer<IndexAndSize>(BufferType::kOutput, kWidth);
    ctx["output"] = output;
    ctx.launch(0, kWidth);
    const auto values = read_buffer<IndexAndSize>(*output);
    for (unsigned x = 0; x < kWidth; ++x) {
        ASSERT_EQ(values[x].index, make_uint3(x, 0, 0)) << "element " << x;
        // Unused dimensions of the launch report size 1.
        ASSERT_EQ(values[x].size, make_uint3(kWidth, 1, 1)) << "element " << x;
    }
}

TEST_F(RayGenerationTest, TwoDimensionalLaunchSeesEveryIndexAndTheSize) {
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(pk_write_index_2d)));
    constexpr unsigned kW = 19, kH = 13;  // partial tiles on both axes
    auto output = ctx.create_buffer<IndexAndSize>(BufferType::kOutput, kW, kH);
    ctx["output"] = output;
    ctx.launch(0, kW, kH);
    const auto values = read_buffer<IndexAndSize>(*output);
    for (unsigned y = 0; y < kH; ++y)
        for (unsigned x = 0; x < kW; ++x) {
            ASSERT_EQ(values[y * kW + x].index, make_uint3(x, y, 0));
            ASSERT_EQ(values[y * kW + x].size, make_uint3(kW, kH, 1));
        }
}

TEST_F(RayGenerationTest, ThreeDimensionalLaunchSeesEveryIndexAndTheSize) {
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(pk_write_index_3d)));
    constexpr unsigned kW = 9, kH = 10, kD = 3;
    auto output = ctx.create_buffer<IndexAndSize>(BufferType::kOutput, kW, kH, kD);
    ctx["output"] = output;
    ctx.launch(0, kW, kH, kD);
    const auto values = read_buffer<IndexAndSize>(*output);
    for (unsigned z = 0; z < kD; ++z)
        for (unsigned y = 0; y < kH; ++y)
            for (unsigned x = 0; x < kW; ++x) {
                const unsigned i = (z * kH + y) * kW + x;
                ASSERT_EQ(values[i].index, make_uint3(x, y, z));
                ASSERT_EQ(values[i].size, make_uint3(kW, kH, kD));
            }
}

TEST_F(RayGenerationTest, SecondLaunchWithAnotherSizeRunsTheNewGrid) {
    // The launch size is a launch argument, not compiled state: relaunching smaller works.
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(pk_write_index_1d)));
    auto output = ctx.create_buffer<IndexAndSize>(BufferType::kOutput, 16);
    ctx["output"] = output;
    ctx.launch(0, 16);
    output->resize(5);
    ctx.launch(0, 5);
    const auto values = read_buffer<IndexAndSize>(*output);
    ASSERT_EQ(values.size(), 5u);
    for (unsigned x = 0; x < 5; ++x) EXPECT_EQ(values[x].size, make_uint3(5, 1, 1));
}

TEST_F(RayGenerationTest, LaunchShapeTrialsEndAndEveryLaunchIsComplete) {
    // The CUDA backend times a few launch shapes on an entry's first launches and says so in
    // the report (benchmarks skip those); the CPU has no shapes. Either way, every launch,
    // trial or not, runs every index.
    constexpr unsigned kWidth = 4099;
    // Without the register-capped variants, which would reopen the tuning when they arrive.
    const ScopedEnv variants("LUCENT_GPU_REGISTER_VARIANTS", "off");
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(pk_write_index_1d)));
    auto output = ctx.create_buffer<IndexAndSize>(BufferType::kOutput, kWidth);
    ctx["output"] = output;
    std::vector<bool> trials;
    for (int launch = 0; launch < 20; ++launch) {
        ctx.launch(0, kWidth);
        trials.push_back(ctx.last_launch().launch_shape_trial);
        const auto values = read_buffer<IndexAndSize>(*output);
        for (unsigned x = 0; x < kWidth; ++x)
            ASSERT_EQ(values[x].index, make_uint3(x, 0, 0)) << "launch " << launch;
    }
    if (test_backend() == BackendKind::kCpu) {
        for (bool trial : trials) EXPECT_FALSE(trial);
        return;
    }
    EXPECT_TRUE(trials.front());  // the first launch warms up shape 0
    // Trials come first and end: once a launch runs the chosen shape, all later ones do.
    const auto first_chosen = std::find(trials.begin(), trials.end(), false);
    ASSERT_NE(first_chosen, trials.end()) << "still trying shapes after 20 launches";
    for (auto it = first_chosen; it != trials.end(); ++it) EXPECT_FALSE(*it);
}

// ---- miss, intersection and closest hit ---------------------------------------

using ClosestHitTest = CasterFixture;

TEST_F(ClosestHitTest, MissProgramRunsWhenNothingIsHitAndReadsItsRecord) {
    ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(pk_miss_background)));
    ctx["background_id"] = 77u;
    auto spheres = make_spheres(ctx, {make_float4(0, 0, 5, 1)});
    auto top = make_geometry_group(
        ctx,
        {make_instance(ctx, spheres,
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 1))});
    const auto hits = cast(top, {cast_ray(make_float3(0, 0, 0), make_float3(0, 0, -1)),
                                 cast_ray(make_float3(0, 0, 0), make_float3(0, 0, 1))});
    EXPECT_EQ(hits[0].hit, 0);
    EXPECT_EQ(hits[0].id, 77u);
    // The miss program sees the ray's full interval: nothing shortened it.
    EXPECT_GE(hits[0].ray_tmax, kInfinity);
    EXPECT_EQ(hits[1].hit, 1) << "the ray along +z hits the sphere: the miss must not run";
}

TEST_F(ClosestHitTest, RegisterCappedVariantGivesTheSameHitsAsTheKernelAsCompiled) {
    // "sync": the CUDA backend compiles the capped variant (64 registers a thread) of this
    // tracing kernel with it, so the tuning's trials run both within the launches below.
    const ScopedEnv variants("LUCENT_GPU_REGISTER_VARIANTS", "sync");
    std::vector<float4> centres;
    for (int i = 0; i < 64; ++i)
        centres.push_back(
            make_float4(float(i % 8) - 3.5f, float(i / 8) - 3.5f, 10.0f + i % 3, 0.45f));
    auto top = make_geometry_group(
        ctx,
        {make_instance(ctx, make_spheres(ctx, centres),
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 1))});
    std::vector<CastRay> rays;
    for (int i = 0; i < 4096; ++i) {
        const float x = float(i % 64) / 8.0f - 4.0f, y = float(i / 64) / 8.0f - 4.0f;
        rays.push_back(cast_ray(make_float3(0, 0, 0), normalize(make_float3(x, y, 10.0f))));
    }
    (*caster)["top"] = top;
    (*caster)["rays"] = input_buffer(ctx, rays);
    auto results = ctx.create_buffer<TestPayload>(BufferType::kOutput, unsigned(rays.size()));
    (*caster)["results"] = results;
    ctx.launch(0, unsigned(rays.size()));
    const std::vector<TestPayload> first = read_buffer<TestPayload>(*results);
    size_t hits = 0;
    for (const TestPayload& h : first) hits += h.hit == 1;
    ASSERT_GT(hits, 1000u);
    bool capped = false;
    for (int launch = 1; launch < 24; ++launch) {
        ctx.launch(0, unsigned(rays.size()));
        const LaunchReport& report = ctx.last_launch();
        capped = capped || report.registers_capped;
        // A capped variant has 64 registers a thread, or 56 with trace() inlined.
        if (report.registers_capped)
            EXPECT_TRUE(report.register_cap == 64 ||
                        (report.register_cap == 56 && report.trace_inlined))
                << report.register_cap;
        else
            EXPECT_EQ(report.register_cap, 0u);
        const std::vector<TestPayload> again = read_buffer<TestPayload>(*results);
        for (size_t i = 0; i < rays.size(); ++i) {
            ASSERT_EQ(again[i].hit, first[i].hit) << "ray " << i << ", launch " << launch;
            ASSERT_EQ(again[i].prim, first[i].prim) << "ray " << i << ", launch " << launch;
            ASSERT_EQ(again[i].t, first[i].t) << "ray " << i << ", launch " << launch;
        }
    }
    // The CPU has no variants; the GPU's tracing kernel uses more than 64 registers.
    EXPECT_EQ(capped, test_backend() == BackendKind::kCuda);
}

TEST_F(ClosestHitTest, CustomSphereIntersectionFeedsAttributesToClosestHit) {
    // The far sphere is primitive 0, the near one primitive 1: closest hit must see the near.
    auto spheres = make_spheres(ctx, {make_float4(0, 0, 10, 1), make_float4(0, 0, 5, 1)});
    auto top = make_geometry_group(
        ctx,
        {make_instance(ctx, spheres,
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 3))});
    const auto hits = cast(top, {cast_ray(make_float3(0, 0, 0), make_float3(0, 0, 1)),
                                 cast_ray(make_float3(0, 0, 20), make_float3(0, 0, -1)),
                                 cast_ray(make_float3(3, 0, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].id, 3u);
    EXPECT_EQ(hits[0].prim, 1u);
    EXPECT_NEAR(hits[0].t, 4.0f, kEps);
    EXPECT_FLOAT3_NEAR(hits[0].point, make_float3(0, 0, 4), kEps);
    EXPECT_FLOAT3_NEAR(hits[0].normal, make_float3(0, 0, -1), kEps);

    ASSERT_EQ(hits[1].hit, 1);
    EXPECT_EQ(hits[1].prim, 0u);
    EXPECT_NEAR(hits[1].t, 9.0f, kEps);
    EXPECT_FLOAT3_NEAR(hits[1].normal, make_float3(0, 0, 1), kEps);

    EXPECT_EQ(hits[2].hit, 0) << "x = 3 passes beside both unit spheres";
}

TEST_F(ClosestHitTest, OffAxisSphereHitHasAnalyticNormal) {
    auto spheres = make_spheres(ctx, {make_float4(1, 2, 6, 2)});
    auto top = make_geometry_group(
        ctx,
        {make_instance(ctx, spheres,
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 0))});
    // Enters the sphere where (x - 1)^2 + (z - 6)^2 = 4 with x = 2: z = 6 - sqrt(3).
    const auto hits = cast(top, {cast_ray(make_float3(2, 2, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    const float z = 6.0f - std::sqrt(3.0f);
    EXPECT_NEAR(hits[0].t, z, kEps);
    EXPECT_FLOAT3_NEAR(hits[0].normal, make_float3(0.5f, 0, (z - 6.0f) / 2.0f), kEps);
}

TEST_F(ClosestHitTest, ParallelogramIntersectionReportsItsCoordinates) {
    auto geometry = ctx.create_geometry();
    geometry->set_primitive_count(1);
    geometry->set_bounding_box_program(program(ctx, LUCENT_PROGRAM(pk_parallelogram_bounds)));
    geometry->set_intersection_program(program(ctx, LUCENT_PROGRAM(pk_parallelogram_intersect)));
    (*geometry)["anchor"] = make_float3(-1, -1, 3);
    (*geometry)["v1"] = make_float3(2, 0, 0);
    (*geometry)["v2"] = make_float3(0, 4, 0);
    auto top = make_geometry_group(
        ctx,
        {make_instance(ctx, geometry,
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(pk_parallelogram_hit)), 9))});
    const auto hits = cast(top, {cast_ray(make_float3(0.5f, 1, 0), make_float3(0, 0, 1)),
                                 cast_ray(make_float3(2, 0, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].id, 9u);
    EXPECT_NEAR(hits[0].t, 3.0f, kEps);
    EXPECT_NEAR(hits[0].uv.x, 0.75f, kEps);
    EXPECT_NEAR(hits[0].uv.y, 0.5f, kEps);
    EXPECT_EQ(hits[1].hit, 0) << "x = 2 is beyond the parallelogram's edge at x = 1";
}

TEST_F(ClosestHitTest, RayIntervalLimitsBothTrianglesAndCustomPrimitives) {
    // A square at z = 5 and a unit sphere centred at (3, 0, 5) (front at z = 4).
    auto quad =
        make_instance(ctx, make_triangles(ctx, square_at(5, -1, 1, -1, 1)),
                      make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1));
    auto ball =
        make_instance(ctx, make_spheres(ctx, {make_float4(3, 0, 5, 1)}),
                      make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 2));
    auto top = make_geometry_group(ctx, {quad, ball});
    auto gen = program(ctx, LUCENT_PROGRAM(pk_cast_rays));
    ctx.set_ray_generation_program(0, gen);
    const float3 z = make_float3(0, 0, 1);
    const std::vector<Ray> rays = {
        make_ray(make_float3(0, 0, 0), z, 0, 0.0f, 4.5f),  // ends before the square
        make_ray(make_float3(0, 0, 0), z, 0, 0.0f, 5.5f),  // reaches it
        make_ray(make_float3(0, 0, 0), z, 0, 5.5f),        // starts behind it
        make_ray(make_float3(3, 0, 0), z, 0, 0.0f, 3.5f),  // ends before the sphere
        make_ray(make_float3(3, 0, 0), z, 0, 0.0f, 4.5f),  // reaches its front
        make_ray(make_float3(3, 0, 0), z, 0, 4.5f),        // starts inside: sees the back
    };
    (*gen)["top"] = top;
    (*gen)["ray_list"] = input_buffer(ctx, rays);
    auto results = ctx.create_buffer<TestPayload>(BufferType::kOutput, unsigned(rays.size()));
    (*gen)["results"] = results;
    ctx.launch(0, unsigned(rays.size()));
    const auto hits = read_buffer<TestPayload>(*results);
    EXPECT_EQ(hits[0].hit, 0);
    ASSERT_EQ(hits[1].hit, 1);
    EXPECT_NEAR(hits[1].t, 5.0f, kEps);
    EXPECT_NEAR(hits[1].ray_tmax, 5.5f, kEps) << "current_ray() keeps the interval traced";
    EXPECT_EQ(hits[2].hit, 0);
    EXPECT_EQ(hits[3].hit, 0);
    ASSERT_EQ(hits[4].hit, 1);
    EXPECT_NEAR(hits[4].t, 4.0f, kEps);
    ASSERT_EQ(hits[5].hit, 1);
    EXPECT_NEAR(hits[5].t, 6.0f, kEps);
}

TEST_F(ClosestHitTest, TrianglesAndCustomPrimitivesInOneGroupGiveTheNearestHit) {
    // Along x = 0: sphere front at z = 4, square at z = 6; along x = 0.5 the square is
    // moved in front (z = 3) for a second group. Order of instances must not matter.
    auto ball =
        make_instance(ctx, make_spheres(ctx, {make_float4(0, 0, 5, 1)}),
                      make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 1));
    auto far_quad =
        make_instance(ctx, make_triangles(ctx, square_at(6)),
                      make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 2));
    auto near_quad =
        make_instance(ctx, make_triangles(ctx, square_at(3)),
                      make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 3));
    const std::vector<CastRay> rays = {cast_ray(make_float3(0, 0, 0), make_float3(0, 0, 1))};
    EXPECT_EQ(cast(make_geometry_group(ctx, {far_quad, ball}), rays)[0].id, 1u);
    EXPECT_EQ(cast(make_geometry_group(ctx, {ball, far_quad}), rays)[0].id, 1u);
    EXPECT_EQ(cast(make_geometry_group(ctx, {ball, near_quad}), rays)[0].id, 3u);
    EXPECT_EQ(cast(make_geometry_group(ctx, {near_quad, ball}), rays)[0].id, 3u);
}

// ---- built-in triangles --------------------------------------------------------

using TriangleTest = CasterFixture;

TEST_F(TriangleTest, BarycentricsAndNormalWithoutIndexBuffer) {
    // Triangle 0 at z = 2; triangle 1 elsewhere at z = 4.
    auto triangles =
        make_triangles(ctx, {make_float3(0, 0, 2), make_float3(1, 0, 2), make_float3(0, 1, 2),
                             make_float3(5, 0, 4), make_float3(6, 0, 4), make_float3(5, 1, 4)});
    auto top = make_geometry_group(
        ctx,
        {make_instance(ctx, triangles,
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 4))});
    const auto hits = cast(top, {cast_ray(make_float3(0.2f, 0.3f, 0), make_float3(0, 0, 1)),
                                 cast_ray(make_float3(5.6f, 0.25f, 0), make_float3(0, 0, 1)),
                                 cast_ray(make_float3(0.8f, 0.8f, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].prim, 0u);
    EXPECT_NEAR(hits[0].t, 2.0f, kEps);
    // (u, v) are the weights of vertices 1 and 2.
    EXPECT_NEAR(hits[0].uv.x, 0.2f, kEps);
    EXPECT_NEAR(hits[0].uv.y, 0.3f, kEps);
    // The geometric normal is perpendicular to the triangle (orientation is not asserted).
    EXPECT_NEAR(std::fabs(hits[0].normal.z), 1.0f, kEps);

    ASSERT_EQ(hits[1].hit, 1);
    EXPECT_EQ(hits[1].prim, 1u);
    EXPECT_NEAR(hits[1].t, 4.0f, kEps);
    EXPECT_NEAR(hits[1].uv.x, 0.6f, kEps);
    EXPECT_NEAR(hits[1].uv.y, 0.25f, kEps);

    EXPECT_EQ(hits[2].hit, 0) << "(0.8, 0.8) is outside the triangle u + v <= 1";
}

TEST_F(TriangleTest, IndexBufferSelectsTheVertices) {
    // The same triangle as above with vertices stored out of order plus an unused one.
    auto triangles = make_triangles(
        ctx,
        {make_float3(9, 9, 9), make_float3(0, 1, 2), make_float3(0, 0, 2), make_float3(1, 0, 2)},
        {make_uint3(2, 3, 1)});
    auto top = make_geometry_group(
        ctx,
        {make_instance(ctx, triangles,
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 4))});
    const auto hits = cast(top, {cast_ray(make_float3(0.2f, 0.3f, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_NEAR(hits[0].t, 2.0f, kEps);
    EXPECT_NEAR(hits[0].uv.x, 0.2f, kEps);
    EXPECT_NEAR(hits[0].uv.y, 0.3f, kEps);
}

TEST_F(TriangleTest, AttributeProgramInterpolatesTexcoords) {
    const std::vector<uint3> indices = {make_uint3(0, 1, 2), make_uint3(3, 4, 5)};
    auto triangles =
        make_triangles(ctx,
                       {make_float3(0, 0, 2), make_float3(1, 0, 2), make_float3(0, 1, 2),
                        make_float3(5, 0, 2), make_float3(6, 0, 2), make_float3(5, 1, 2)},
                       indices);
    triangles->set_attribute_program(program(ctx, LUCENT_PROGRAM(pk_texcoord_attributes)));
    // The attribute program's record resolves on the geometry (Program, GI, Geometry, Context).
    (*triangles)["indices"] = triangles->indices();
    (*triangles)["texcoords"] = input_buffer(
        ctx, std::vector<float2>{make_float2(0, 0), make_float2(10, 0), make_float2(0, 20),
                                 make_float2(1, 1), make_float2(1, 1), make_float2(3, 5)});
    auto top = make_geometry_group(
        ctx, {make_instance(ctx, triangles,
                            make_material(ctx, program(ctx, LUCENT_PROGRAM(pk_texcoord_hit)), 4))});
    const auto hits = cast(top, {cast_ray(make_float3(0.2f, 0.3f, 0), make_float3(0, 0, 1)),
                                 cast_ray(make_float3(5.5f, 0.5f, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].prim, 0u);
    EXPECT_NEAR(hits[0].uv.x, 0.2f * 10, kEps);
    EXPECT_NEAR(hits[0].uv.y, 0.3f * 20, kEps);
    ASSERT_EQ(hits[1].hit, 1);
    EXPECT_EQ(hits[1].prim, 1u);
    // u = v = 0.5 on triangle 1: 0 * (1,1) + 0.5 * (1,1) + 0.5 * (3,5).
    EXPECT_NEAR(hits[1].uv.x, 2.0f, kEps);
    EXPECT_NEAR(hits[1].uv.y, 3.0f, kEps);
}

TEST_F(TriangleTest, PerTriangleMaterialIndexBufferSelectsTheMaterial) {
    auto triangles =
        make_triangles(ctx, {make_float3(0, 0, 2), make_float3(1, 0, 2), make_float3(0, 1, 2),
                             make_float3(5, 0, 2), make_float3(6, 0, 2), make_float3(5, 1, 2)});
    triangles->set_material_indices(input_buffer(ctx, std::vector<unsigned>{1, 0}));
    auto closest = program(ctx, LUCENT_PROGRAM(common_triangle_hit));
    auto instance = make_instance(ctx, triangles, make_material(ctx, closest, 100));
    instance->add_material(make_material(ctx, closest, 101));
    auto top = make_geometry_group(ctx, {instance});
    const auto hits = cast(top, {cast_ray(make_float3(0.2f, 0.2f, 0), make_float3(0, 0, 1)),
                                 cast_ray(make_float3(5.2f, 0.2f, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].id, 101u) << "triangle 0 uses material 1";
    ASSERT_EQ(hits[1].hit, 1);
    EXPECT_EQ(hits[1].id, 100u) << "triangle 1 uses material 0";
}

TEST_F(ClosestHitTest, ReportedMaterialIndexSelectsAmongTheInstanceMaterials) {
    auto geometry = make_spheres(
        ctx, {make_float4(-3, 0, 5, 1), make_float4(0, 0, 5, 1), make_float4(3, 0, 5, 1)});
    geometry->set_intersection_program(program(ctx, LUCENT_PROGRAM(pk_sphere_intersect_material)));
    (*geometry)["sphere_materials"] = input_buffer(ctx, std::vector<unsigned>{2, 0, 1});
    auto closest = program(ctx, LUCENT_PROGRAM(common_sphere_hit));
    auto instance = make_instance(ctx, geometry, make_material(ctx, closest, 100));
    instance->add_material(make_material(ctx, closest, 101));
    instance->add_material(make_material(ctx, closest, 102));
    auto top = make_geometry_group(ctx, {instance});
    const auto hits = cast(top, {cast_ray(make_float3(-3, 0, 0), make_float3(0, 0, 1)),
                                 cast_ray(make_float3(0, 0, 0), make_float3(0, 0, 1)),
                                 cast_ray(make_float3(3, 0, 0), make_float3(0, 0, 1))});
    EXPECT_EQ(hits[0].id, 102u);
    EXPECT_EQ(hits[1].id, 100u);
    EXPECT_EQ(hits[2].id, 101u);
}

TEST_F(ClosestHitTest, ClosestHitSeesTHitAndTheWorldRay) {
    // A non-unit direction: t is in units of the direction, not of distance.
    auto quad = make_triangles(ctx, square_at(5));
    auto top = make_geometry_group(
        ctx,
        {make_instance(ctx, quad,
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1))});
    const auto hits = cast(top, {cast_ray(make_float3(1, 2, -3), make_float3(0, 0, 2))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_NEAR(hits[0].t, 4.0f, kEps);
    EXPECT_FLOAT3_NEAR(hits[0].ray_origin, make_float3(1, 2, -3), kEps);
    EXPECT_FLOAT3_NEAR(hits[0].ray_direction, make_float3(0, 0, 2), kEps);
    EXPECT_FLOAT3_NEAR(hits[0].point, make_float3(1, 2, 5), kEps);
}

// ---- any hit --------------------------------------------------------------------

class AnyHitTest : public CasterFixture {
  protected:
    /// A square at depth z with its own material (id = z) and optional any-hit program.
    std::shared_ptr<GeometryInstance> plane(float z, std::shared_ptr<Program> any_hit) {
        auto material =
            make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), unsigned(z));
        if (any_hit) material->set_any_hit(0, any_hit);
        return make_instance(ctx, make_triangles(ctx, square_at(z)), material);
    }
    const std::vector<CastRay> rays = {cast_ray(make_float3(0.3f, 0.1f, 0), make_float3(0, 0, 1))};
};

TEST_F(AnyHitTest, IgnoreIntersectionLetsTheRayPassToAFartherSurface) {
    auto ignore = program(ctx, LUCENT_PROGRAM(pk_anyhit_ignore));
    auto top = make_geometry_group(ctx, {plane(2, ignore), plane(5, nullptr)});
    const auto hits = cast(top, rays);
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].id, 5u) << "the near plane's any-hit ignored it";
    EXPECT_NEAR(hits[0].t, 5.0f, kEps);
    EXPECT_EQ(hits[0].anyhit_count, 1u);
    EXPECT_NEAR(hits[0].anyhit_t, 2.0f, kEps) << "t_hit() in any-hit is the candidate's t";
}

TEST_F(AnyHitTest, IgnoringEverySurfaceEndsInTheMissProgram) {
    auto ignore = program(ctx, LUCENT_PROGRAM(pk_anyhit_ignore));
    auto top = make_geometry_group(ctx, {plane(2, ignore), plane(5, ignore)});
    const auto hits = cast(top, rays);
    EXPECT_EQ(hits[0].hit, 0);
    // Whatever the order, both candidates reach any-hit: neither was accepted.
    EXPECT_EQ(hits[0].anyhit_count, 2u);
}

TEST_F(AnyHitTest, TerminateRayAcceptsTheHitAndStillRunsClosestHit) {
    // OptiX semantics: terminate_ray() accepts the candidate, stops traversal, and the
    // closest-hit program runs for the accepted (terminated) hit.
    auto terminate = program(ctx, LUCENT_PROGRAM(pk_anyhit_terminate));
    auto top =
        make_geometry_group(ctx, {plane(2, terminate), plane(4, terminate), plane(6, terminate)});
    const auto hits = cast(top, rays);
    ASSERT_EQ(hits[0].hit, 1) << "closest hit must run after terminate_ray";
    EXPECT_EQ(hits[0].anyhit_count, 1u) << "traversal stops at the first accepted candidate";
    EXPECT_NEAR(hits[0].t, hits[0].anyhit_t, kEps) << "closest hit sees the terminated hit";
    EXPECT_EQ(float(hits[0].id), hits[0].t) << "and that hit's material";
}

TEST_F(AnyHitTest, TerminateOnTheNearSurfaceIsNeverReplacedByAFartherOne) {
    auto terminate = program(ctx, LUCENT_PROGRAM(pk_anyhit_terminate));
    auto top = make_geometry_group(ctx, {plane(5, nullptr), plane(2, terminate)});
    const auto hits = cast(top, rays);
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].id, 2u);
    EXPECT_NEAR(hits[0].t, 2.0f, kEps);
}

TEST_F(AnyHitTest, TerminateRayStopsTraversalAcrossTheChildrenOfAGroup) {
    // Three planes, each in its own geometry group under one Group.
    auto terminate = program(ctx, LUCENT_PROGRAM(pk_anyhit_terminate));
    auto top = ctx.create_group();
    for (float z : {6.0f, 2.0f, 4.0f})
        top->add_child(make_geometry_group(ctx, {plane(z, terminate)}));
    const auto hits = cast(top, rays);
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].anyhit_count, 1u) << "no other group is entered after terminate_ray";
    EXPECT_NEAR(hits[0].t, hits[0].anyhit_t, kEps);
}

TEST_F(AnyHitTest, AnyHitRunsForEveryCandidateUntilTheClosestIsFound) {
    // Any-hit that neither ignores nor terminates just observes: the closest still wins.
    auto count = program(ctx, LUCENT_PROGRAM(pk_anyhit_count));
    auto top = make_geometry_group(ctx, {plane(2, count)});
    const auto hits = cast(top, rays);
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].id, 2u);
    EXPECT_EQ(hits[0].anyhit_count, 1u);
}

TEST_F(AnyHitTest, IgnoredSphereEntryMakesTheIntersectionReportItsExit) {
    // report_intersection() returns false when any-hit ignores: the sphere program then
    // reports its far root, which any-hit accepts.
    auto any = program(ctx, LUCENT_PROGRAM(pk_anyhit_ignore_near_sphere));
    (*any)["ignore_before"] = 5.0f;
    auto material = make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 1);
    material->set_any_hit(0, any);
    auto top = make_geometry_group(
        ctx, {make_instance(ctx, make_spheres(ctx, {make_float4(0, 0, 5, 1)}), material)});
    const auto hits = cast(top, {cast_ray(make_float3(0, 0, 0), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_NEAR(hits[0].t, 6.0f, kEps);
    EXPECT_FLOAT3_NEAR(hits[0].normal, make_float3(0, 0, 1), kEps);
    EXPECT_EQ(hits[0].anyhit_count, 2u);
}

TEST_F(AnyHitTest, AnyHitSeesTheCandidatesBarycentricsForCutouts) {
    // Holes where u > 0.5 on the near square: such rays reach the far square.
    auto cutout = program(ctx, LUCENT_PROGRAM(pk_anyhit_cutout));
    auto near_material = make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 2);
    near_material->set_any_hit(0, cutout);
    // One triangle (0,0)-(1,0)-(0,1) at z = 2, so u = x and v = y.
    auto near = make_instance(
        ctx,
        make_triangles(ctx, {make_float3(0, 0, 2), make_float3(1, 0, 2), make_float3(0, 1, 2)}),
        near_material);
    auto top = make_geometry_group(ctx, {near, plane(5, nullptr)});
    const auto hits = cast(top, {cast_ray(make_float3(0.2f, 0.1f, 0), make_float3(0, 0, 1)),
                                 cast_ray(make_float3(0.7f, 0.1f, 0), make_float3(0, 0, 1))});
    EXPECT_EQ(hits[0].id, 2u) << "u = 0.2 is solid";
    EXPECT_EQ(hits[1].id, 5u) << "u = 0.7 is a hole";
    EXPECT_NEAR(hits[1].t, 5.0f, kEps);
}

TEST_F(AnyHitTest, AnyHitSeesAttributeProgramAttributes) {
    // Attributes of an attribute program reach any-hit too (the attribute program runs once for
    // the closest hit and once for each any-hit candidate).
    const std::vector<uint3> indices = {make_uint3(0, 1, 2)};
    auto triangles = make_triangles(
        ctx, {make_float3(0, 0, 2), make_float3(1, 0, 2), make_float3(0, 1, 2)}, indices);
    triangles->set_attribute_program(program(ctx, LUCENT_PROGRAM(pk_texcoord_attributes)));
    (*triangles)["indices"] = triangles->indices();
    (*triangles)["texcoords"] = input_buffer(
        ctx, std::vector<float2>{make_float2(0, 0), make_float2(10, 0), make_float2(0, 10)});
    auto material = make_material(ctx, program(ctx, LUCENT_PROGRAM(pk_texcoord_hit)), 2);
    material->set_any_hit(0, program(ctx, LUCENT_PROGRAM(pk_anyhit_texcoord_cutout)));
    auto top =
        make_geometry_group(ctx, {make_instance(ctx, triangles, material), plane(5, nullptr)});
    const auto hits = cast(top, {cast_ray(make_float3(0.2f, 0.1f, 0), make_float3(0, 0, 1)),
                                 cast_ray(make_float3(0.7f, 0.1f, 0), make_float3(0, 0, 1))});
    EXPECT_EQ(hits[0].id, 2u) << "texcoord x = 2 is solid";
    EXPECT_NEAR(hits[0].uv.x, 2.0f, kEps);
    EXPECT_EQ(hits[1].id, 5u) << "texcoord x = 7 is a hole";
}

// ---- callables ---------------------------------------------------------------------

TEST_F(RayGenerationTest, CallableBoundThroughAVariableRunsWithItsOwnRecord) {
    auto caller = program(ctx, LUCENT_PROGRAM(pk_call));
    ctx.set_ray_generation_program(0, caller);
    auto scale = program(ctx, LUCENT_PROGRAM(pk_scale));
    (*scale)["factor"] = 2.0f;  // on the callable's own scope
    (*caller)["shade"] = scale;
    auto output = ctx.create_buffer<float3>(BufferType::kOutput, 4);
    ctx["output"] = output;
    ctx.launch(0, 4);
    auto values = read_buffer<float3>(*output);
    for (unsigned i = 0; i < 4; ++i)
        EXPECT_FLOAT3_NEAR(values[i], make_float3(2.0f * i, 2, -4), kEps);

    // Rebinding the variable to another callable of the same signature switches programs.
    auto offset = program(ctx, LUCENT_PROGRAM(pk_offset));
    (*offset)["offset"] = make_float3(10, 20, 30);
    (*caller)["shade"] = offset;
    ctx.launch(0, 4);
    values = read_buffer<float3>(*output);
    for (unsigned i = 0; i < 4; ++i)
        EXPECT_FLOAT3_NEAR(values[i], make_float3(10.0f + i, 21, 28), kEps);
}

// ---- recursion ---------------------------------------------------------------------

TEST_F(ClosestHitTest, ClosestHitTracesRecursivelyToTheRequestedDepth) {
    // Two mirrors at z = 0 and z = 2; the ray starts between them at z = 1.
    auto bounce = program(ctx, LUCENT_PROGRAM(pk_bounce));
    auto material = ctx.create_material();
    material->set_closest_hit(0, bounce);
    (*material)["bounces"] = 5;
    std::vector<float3> vertices = square_at(0);
    const std::vector<float3> far = square_at(2);
    vertices.insert(vertices.end(), far.begin(), far.end());
    auto top =
        make_geometry_group(ctx, {make_instance(ctx, make_triangles(ctx, vertices), material)});
    ctx["top"] = top;
    ctx.set_max_recursion_depth(8);
    const auto hits = cast(top, {cast_ray(make_float3(0.3f, 0.1f, 1), make_float3(0, 0, 1))});
    ASSERT_EQ(hits[0].hit, 1);
    EXPECT_EQ(hits[0].depth, 5);
    // 1 to the first mirror, then 2 per bounce for the remaining four traces.
    EXPECT_NEAR(hits[0].path_length, 9.0f, 1e-3f);
    EXPECT_EQ(ctx.last_launch().exception_count(), 0u);
}

// ---- print -------------------------------------------------------------------------

/// The line a print program writes for index i (snprintf, like the device print).
std::string print_line(const char* format, unsigned i) {
    char line[128];
    std::snprintf(line, sizeof line, format, i);
    return line;
}

class PrintTest : public RayGenerationTest {
  protected:
    PrintTest() { ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(pk_print_index))); }
    std::string launch_and_capture(unsigned width) {
        testing::internal::CaptureStdout();
        ctx.launch(0, width);
        std::fflush(stdout);
        return testing::internal::GetCapturedStdout();
    }
};

TEST_F(PrintTest, NothingIsPrintedWhilePrintingIsDisabled) {
    EXPECT_FALSE(ctx.print_enabled()) << "printing is off by default";
    EXPECT_THAT(launch_and_capture(8), Not(HasSubstr("lucent-print-test")));
}

TEST_F(PrintTest, EveryIndexPrintsWhenEnabledWithoutAnIndexFilter) {
    ctx.set_print_enabled(true);
    const std::string out = launch_and_capture(8);
    for (unsigned i = 0; i < 8; ++i)
        EXPECT_THAT(out, HasSubstr(print_line("lucent-print-test index=%u\n", i)));
}

TEST_F(PrintTest, OnlyTheSelectedLaunchIndexPrints) {
    ctx.set_print_enabled(true);
    ctx.set_print_launch_index(5);
    const std::string out = launch_and_capture(8);
    EXPECT_THAT(out, HasSubstr("lucent-print-test index=5\n"));
    for (unsigned i = 0; i < 8; ++i) {
        if (i == 5) continue;
        EXPECT_THAT(out, Not(HasSubstr(print_line("lucent-print-test index=%u\n", i))));
    }
}

TEST_F(PrintTest, TwoDimensionalIndexFilterMatchesBothCoordinates) {
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(pk_print_index_2d)));
    ctx.set_print_enabled(true);
    ctx.set_print_launch_index(2, 1);
    testing::internal::CaptureStdout();
    ctx.launch(0, 4, 3);
    std::fflush(stdout);
    const std::string out = testing::internal::GetCapturedStdout();
    EXPECT_EQ(out, "lucent-print-2d 2,1\n");
}

TEST_F(PrintTest, AnyCoordinateMinusOneMatchesAWholeRow) {
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(pk_print_index_2d)));
    ctx.set_print_enabled(true);
    ctx.set_print_launch_index(-1, 2);
    testing::internal::CaptureStdout();
    ctx.launch(0, 4, 3);
    std::fflush(stdout);
    const std::string out = testing::internal::GetCapturedStdout();
    for (unsigned x = 0; x < 4; ++x)
        EXPECT_THAT(out, HasSubstr(print_line("lucent-print-2d %u,2\n", x)));
    EXPECT_THAT(out, Not(HasSubstr(",1\n")));
    EXPECT_THAT(out, Not(HasSubstr(",0\n")));
}

TEST_F(ClosestHitTest, PrintFromAClosestHitFollowsTheLaunchIndexFilter) {
    auto top = make_geometry_group(
        ctx, {make_instance(ctx, make_triangles(ctx, square_at(2)),
                            make_material(ctx, program(ctx, LUCENT_PROGRAM(pk_print_hit)), 1))});
    ctx.set_print_enabled(true);
    ctx.set_print_launch_index(3);
    testing::internal::CaptureStdout();
    cast(top, std::vector<CastRay>(6, cast_ray(make_float3(0.3f, 0.1f, 0), make_float3(0, 0, 1))));
    std::fflush(stdout);
    EXPECT_EQ(testing::internal::GetCapturedStdout(), "lucent-print-hit 3,0\n");
}

TEST_F(ClosestHitTest, PrintInABoundingBoxProgramDoesNotCrash) {
    // Bounding boxes are computed by the acceleration build, outside any launch index.
    // Run in a child process: a crash must fail this test, not end the whole binary.
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    for (bool enabled : {false, true}) {
        EXPECT_EXIT(
            {
                auto spheres = make_spheres(ctx, {make_float4(0, 0, 5, 1)});
                spheres->set_bounding_box_program(
                    program(ctx, LUCENT_PROGRAM(pk_printing_sphere_bounds)));
                auto top = make_geometry_group(
                    ctx,
                    {make_instance(
                        ctx, spheres,
                        make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 1))});
                ctx.set_print_enabled(enabled);
                const auto hits = cast(top, {cast_ray(make_float3(0, 0, 0), make_float3(0, 0, 1))});
                std::exit(hits[0].hit == 1 ? 0 : 3);
            },
            testing::ExitedWithCode(0), "")
            << "printing " << (enabled ? "enabled" : "disabled");
    }
}

// ---- textures ----------------------------------------------------------------------

class TextureTest : public RayGenerationTest {
  protected:
    TextureTest() {
        ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(pk_sample_texture)));
        // A 4x1 texture whose texel i holds (i, 10 i, 0, 1).
        auto texels = ctx.create_buffer<float4>(BufferType::kInput, 4, 1);
        texels->upload(std::vector<float4>{make_float4(0, 0, 0, 1), make_float4(1, 10, 0, 1),
                                           make_float4(2, 20, 0, 1), make_float4(3, 30, 0, 1)});
        sampler = ctx.create_texture_sampler();
        sampler->set_buffer(texels);
        ctx["tex"] = sampler;
    }
    /// The x channel sampled at each u (v = 0.5, the only row).
    std::vector<float> sample(const std::vector<float>& us) {
        std::vector<float2> uvs;
        for (float u : us) uvs.push_back(make_float2(u, 0.5f));
        ctx["uvs"] = input_buffer(ctx, uvs);
        auto output = ctx.create_buffer<float4>(BufferType::kOutput, unsigned(us.size()));
        ctx["output"] = output;
        ctx.launch(0, unsigned(us.size()));
        std::vector<float> xs;
        for (const float4& v : read_buffer<float4>(*output)) xs.push_back(v.x);
        return xs;
    }
    std::shared_ptr<TextureSampler> sampler;
};

TEST_F(TextureTest, BilinearFilterInterpolatesBetweenTexelCentres) {
    sampler->set_filter(FilterMode::kLinear);
    sampler->set_wrap_mode(WrapMode::kClampToEdge, WrapMode::kClampToEdge);
    // Texel centres are at (i + 0.5) / 4; a quarter of the way from texel 1 to 2 is 1.25.
    const auto xs = sample({1.5f / 4, 1.75f / 4, 2.5f / 4});
    EXPECT_NEAR(xs[0], 1.0f, kEps);
    EXPECT_NEAR(xs[1], 1.25f, kEps);
    EXPECT_NEAR(xs[2], 2.0f, kEps);
}

TEST_F(TextureTest, WrapModesDecideTexelsOutsideTheImage) {
    // u = -0.25 lies halfway between virtual texels -2 and -1.
    sampler->set_wrap_mode(WrapMode::kRepeat, WrapMode::kRepeat);
    EXPECT_NEAR(sample({-0.25f})[0], 2.5f, kEps) << "repeat: texels 2 and 3";
    sampler->set_wrap_mode(WrapMode::kClampToEdge, WrapMode::kClampToEdge);
    EXPECT_NEAR(sample({-0.25f})[0], 0.0f, kEps) << "clamp: texel 0 twice";
    sampler->set_wrap_mode(WrapMode::kMirror, WrapMode::kMirror);
    EXPECT_NEAR(sample({-0.25f})[0], 0.5f, kEps) << "mirror: texels 1 and 0";
}

TEST_F(TextureTest, NearestFilterReturnsTheTexelUnderUv) {
    sampler->set_filter(FilterMode::kNearest);
    sampler->set_wrap_mode(WrapMode::kRepeat, WrapMode::kRepeat);
    const auto xs = sample({0.1f, 0.3f, 0.6f, 0.9f, 1.1f});
    EXPECT_EQ(xs, (std::vector<float>{0, 1, 2, 3, 0}));
}

}  // namespace
}  // namespace lucent_tests

// trace_deferred() and occluded_deferred(): rays a ray-generation program does not wait
// for. Whatever the graph, their programs must write what trace() and occluded() give (on
// the CPU, GeometryGroups of triangles answer them as ray streams, other roots one ray at a
// time); their programs see the deferring launch index and its exceptions; a payload that
// would be gone when the ray is traced is refused; elsewhere than in ray generation they
// are traced at once.
#include <random>

#include "tests/mesh_fixtures.h"
#include "tests/programs/deferred_programs.h"
#include "tests/programs/exception_programs.h"
#include "tests/test_support.h"

namespace {

using namespace lucent;
using namespace lucent_tests;

class DeferredRaysTest : public testing::Test {
  protected:
    explicit DeferredRaysTest(unsigned cpu_threads = 2) : ctx(options(cpu_threads)) {
        ctx.set_entry_point_count(1);
        ctx.set_ray_type<TestPayload>(0, "radiance");
        ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(common_miss)));
    }

    static ContextOptions options(unsigned cpu_threads) {
        ContextOptions o = test_context_options();
        o.threads = cpu_threads;
        return o;
    }

    /// The payloads of `rays` cast by ray-generation program `caster` against `top` (with
    /// `backward`, also the buffer of the rays cast back).
    std::vector<TestPayload> cast(const ProgramDesc& caster, std::shared_ptr<Node> top,
                                  const std::vector<CastRay>& rays,
                                  std::vector<TestPayload>* backward = nullptr) {
        auto results = ctx.create_buffer<TestPayload>(BufferType::kOutput, unsigned(rays.size()));
        auto back = ctx.create_buffer<TestPayload>(BufferType::kOutput, unsigned(rays.size()));
        auto gen = program(ctx, caster);
        (*gen)["top"] = top;
        (*gen)["rays"] = input_buffer(ctx, rays);
        (*gen)["results"] = results;
        if (backward) (*gen)["backward"] = back;
        ctx.set_ray_generation_program(0, gen);
        ctx.launch(0, unsigned(rays.size()));
        EXPECT_EQ(ctx.last_launch().exception_count(), 0u) << ctx.last_launch().summary();
        if (backward) *backward = read_buffer<TestPayload>(*back);
        return read_buffer<TestPayload>(*results);
    }

    /// Deferred and waited-for casts of `rays` (in one launch) agree, field by field.
    void expect_same_as_trace(std::shared_ptr<Node> top, const std::vector<CastRay>& rays) {
        auto deferred = ctx.create_buffer<TestPayload>(BufferType::kOutput, unsigned(rays.size()));
        auto waited = ctx.create_buffer<TestPayload>(BufferType::kOutput, unsigned(rays.size()));
        auto gen = program(ctx, LUCENT_PROGRAM(deferred_beside_trace));
        (*gen)["top"] = top;
        (*gen)["rays"] = input_buffer(ctx, rays);
        (*gen)["results"] = deferred;
        (*gen)["waited"] = waited;
        ctx.set_ray_generation_program(0, gen);
        ctx.launch(0, unsigned(rays.size()));
        ASSERT_EQ(ctx.last_launch().exception_count(), 0u) << ctx.last_launch().summary();
        const auto a = read_buffer<TestPayload>(*deferred), b = read_buffer<TestPayload>(*waited);
        size_t hits = 0;
        for (size_t i = 0; i < rays.size(); ++i) {
            expect_same_payload(a[i], b[i], i);
            hits += b[i].hit == 1;
        }
        EXPECT_GT(hits, rays.size() / 4) << "the rays should hit something";
    }

    static void expect_same_payload(const TestPayload& a, const TestPayload& b, size_t i) {
        ASSERT_EQ(a.hit, b.hit) << "ray " << i;
        EXPECT_EQ(a.id, b.id) << "ray " << i;
        EXPECT_EQ(a.t, b.t) << "ray " << i;
        EXPECT_EQ(a.prim, b.prim) << "ray " << i;
        EXPECT_EQ(a.anyhit_count, b.anyhit_count) << "ray " << i;
        EXPECT_FLOAT3_NEAR(a.point, b.point, 0.0f);
        EXPECT_FLOAT3_NEAR(a.normal, b.normal, 0.0f);
        EXPECT_FLOAT3_NEAR(a.ray_direction, b.ray_direction, 0.0f);
        EXPECT_EQ(a.uv.x, b.uv.x) << "ray " << i;
        EXPECT_EQ(a.uv.y, b.uv.y) << "ray " << i;
    }

    /// A GeometryGroup of the clutter mesh, one material (closest hit common_triangle_hit).
    std::shared_ptr<GeometryGroup> clutter_group() {
        const test_meshes::Mesh mesh = test_meshes::floor_and_clutter(7, 3000);
        return make_geometry_group(
            ctx, {make_instance(
                     ctx, make_triangles(ctx, mesh.positions, mesh.indices),
                     make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 3))});
    }

    /// `count` rays from above the clutter, down at random angles (some leave the floor).
    static std::vector<CastRay> rays_down(size_t count) {
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> uni(0.0f, 1.0f);
        std::vector<CastRay> rays(count);
        for (CastRay& r : rays)
            r = cast_ray(make_float3(12 * uni(rng) - 1, 12 * uni(rng) - 1, 2.0f),
                         normalize(make_float3(uni(rng) - 0.5f, uni(rng) - 0.5f, -1.0f)));
        return rays;
    }

    Context ctx;
};

TEST_F(DeferredRaysTest, ClosestHitsOfATriangleGroupAreTraceOnes) {
    // More rays than a CPU worker's queue holds (65,536): the queue is traced mid-launch too.
    expect_same_as_trace(clutter_group(), rays_down(150000));
}

/// Eight CPU workers (more than the machine's cores is no matter): they publish full queues
/// mid-launch, take runs of each other's queues between their tiles and share out the
/// rays left at the end (SharedDeferredRays).
class DeferredRaysEightWorkersTest : public DeferredRaysTest {
  protected:
    DeferredRaysEightWorkersTest() : DeferredRaysTest(8) {}
};

TEST_F(DeferredRaysEightWorkersTest, ClosestHitsOfATriangleGroupAreTraceOnes) {
    // About 75K rays a worker: each queue fills at least once.
    expect_same_as_trace(clutter_group(), rays_down(600000));
}

TEST_F(DeferredRaysEightWorkersTest, ALaunchThatFailsLateEndsWithItsError) {
    if (test_backend() != BackendKind::kCpu)
        GTEST_SKIP() << "the GPU traces the ray at once, while the local still exists";
    auto top = clutter_group();
    const auto rays = rays_down(600000);
    expect_error([&] { cast(LUCENT_PROGRAM(deferred_cast_last_into_local), top, rays); },
                 {"trace_deferred()", "local variable", "buffer"});
    // The workers are free again: the next launch runs whole.
    const auto results = cast(LUCENT_PROGRAM(deferred_cast), top, rays);
    size_t hits = 0;
    for (const TestPayload& p : results) hits += p.hit == 1;
    EXPECT_GT(hits, rays.size() / 4);
}

TEST_F(DeferredRaysTest, EveryOtherRootAnswersAsTrace) {
    auto clutter = clutter_group();
    // Under a Transform and a Group: the traversal's general path, one ray at a time.
    auto moved = ctx.create_transform();
    moved->set_matrix(translation(0.5f, -0.25f, 0.1f));
    moved->set_child(clutter);
    auto top = ctx.create_group();
    top->add_child(moved);
    expect_same_as_trace(top, rays_down(5000));

    // A group whose candidates an any-hit program sees (it counts them).
    const test_meshes::Mesh mesh = test_meshes::floor_and_clutter(8, 500);
    auto material = make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 4);
    material->set_any_hit(0, program(ctx, LUCENT_PROGRAM(occlusion_count_all)));
    expect_same_as_trace(
        make_geometry_group(
            ctx, {make_instance(ctx, make_triangles(ctx, mesh.positions, mesh.indices), material)}),
        rays_down(5000));
}

TEST_F(DeferredRaysTest, SeveralRaysAnIndexAndSeveralInstances) {
    // Two instances in one group (the stream's triangles are numbered across them).
    auto above =
        make_instance(ctx, make_triangles(ctx, square_at(5.0f)),
                      make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1));
    auto below =
        make_instance(ctx, make_triangles(ctx, square_at(-3.0f, -4, 4, -4, 4)),
                      make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 2));
    auto top = make_geometry_group(ctx, {above, below});
    std::vector<CastRay> rays, backwards;
    for (int i = 0; i < 64; ++i) {
        // Off the squares' diagonals, where two triangles would tie.
        const float3 from = make_float3(0.3f * i - 9.05f, 0.1f * i - 3.0f, 0.0f);
        rays.push_back(cast_ray(from, make_float3(0, 0, 1)));
        backwards.push_back(cast_ray(from, make_float3(0, 0, -1)));
    }
    std::vector<TestPayload> both_back;
    const auto both = cast(LUCENT_PROGRAM(deferred_cast_both_ways), top, rays, &both_back);
    const auto forward = cast(LUCENT_PROGRAM(common_cast), top, rays);
    const auto back = cast(LUCENT_PROGRAM(common_cast), top, backwards);
    unsigned below_hits = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        expect_same_payload(both[i], forward[i], i);
        expect_same_payload(both_back[i], back[i], i);
        EXPECT_EQ(both[i].id, 1u) << "ray " << i;
        below_hits += both_back[i].hit == 1 ? 1 : 0;
        if (both_back[i].hit == 1) {
            EXPECT_EQ(both_back[i].id, 2u) << "ray " << i;
        }
    }
    EXPECT_GT(below_hits, 10u);
    EXPECT_LT(below_hits, 64u);
}

TEST_F(DeferredRaysTest, OcclusionFlagsAreOccludedOnes) {
    auto clutter = clutter_group();
    auto moved = ctx.create_transform();
    moved->set_matrix(translation(0, 0, 0));
    moved->set_child(clutter);
    auto nested = ctx.create_group();
    nested->add_child(moved);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    std::vector<OcclusionQuery> queries(20000);
    for (size_t i = 0; i < queries.size(); ++i) {
        const float3 from = make_float3(10 * uni(rng), 10 * uni(rng), 0.8f);
        const float3 to = make_float3(10 * uni(rng), 10 * uni(rng), 0.05f + 0.6f * uni(rng));
        queries[i] = OcclusionQuery{from, normalize(to - from), length(to - from),
                                    unsigned(i % 3 == 0)};  // a third by leaf boxes
    }
    for (const auto& top : {std::shared_ptr<Node>(clutter), std::shared_ptr<Node>(nested)}) {
        auto occluded = ctx.create_buffer<unsigned>(BufferType::kOutput, unsigned(queries.size()));
        auto deferred = ctx.create_buffer<unsigned>(BufferType::kOutput, unsigned(queries.size()));
        auto gen = program(ctx, LUCENT_PROGRAM(deferred_beside_occluded));
        (*gen)["top"] = top;
        (*gen)["queries"] = input_buffer(ctx, queries);
        (*gen)["occluded"] = occluded;
        (*gen)["deferred"] = deferred;
        ctx.set_ray_generation_program(0, gen);
        ctx.launch(0, unsigned(queries.size()));
        ASSERT_EQ(ctx.last_launch().exception_count(), 0u) << ctx.last_launch().summary();
        const auto waited = read_buffer<unsigned>(*occluded);
        const auto flags = read_buffer<unsigned>(*deferred);
        size_t blocked = 0;
        for (size_t i = 0; i < queries.size(); ++i) {
            ASSERT_EQ(flags[i], waited[i]) << "query " << i;
            blocked += waited[i];
        }
        EXPECT_GT(blocked, queries.size() / 10);
        EXPECT_LT(blocked, queries.size() * 9 / 10);
    }
}

TEST_F(DeferredRaysTest, HitProgramsSeeTheDeferringIndexAndRaiseForIt) {
    ctx.set_exception_enabled(kAllExceptions, true);
    auto material = ctx.create_material();
    material->set_closest_hit(0, program(ctx, LUCENT_PROGRAM(deferred_index_hit)));
    auto top = make_geometry_group(
        ctx, {make_instance(ctx, make_triangles(ctx, square_at(4.0f)), material)});
    auto infos = ctx.create_buffer<ExceptionInfo>(BufferType::kOutput, 6);
    auto log = program(ctx, LUCENT_PROGRAM(et_log_exception));
    (*log)["infos"] = infos;
    ctx.set_exception_program(0, log);
    std::vector<CastRay> rays;
    for (int i = 0; i < 6; ++i)
        rays.push_back(cast_ray(make_float3(float(i), 0, 0), make_float3(0, 0, 1)));
    auto results = ctx.create_buffer<TestPayload>(BufferType::kOutput, 6);
    auto gen = program(ctx, LUCENT_PROGRAM(deferred_cast));
    (*gen)["top"] = top;
    (*gen)["rays"] = input_buffer(ctx, rays);
    (*gen)["results"] = results;
    ctx.set_ray_generation_program(0, gen);
    ctx.launch(0, 6);
    const auto payloads = read_buffer<TestPayload>(*results);
    const auto logged = read_buffer<ExceptionInfo>(*infos);
    for (unsigned i = 0; i < 6; ++i) {
        EXPECT_EQ(payloads[i].hit, 1) << "index " << i;
        EXPECT_EQ(payloads[i].id, i) << "the closest hit sees the launch index that deferred it";
        EXPECT_FLOAT_EQ(payloads[i].t, 4.0f);
        if (i % 2 == 0) {
            EXPECT_EQ(logged[i].code, 0) << "index " << i;
        } else {
            EXPECT_EQ(logged[i].code, kUserExceptionBase + 7) << "index " << i;
            EXPECT_EQ(logged[i].launch_index.x, i);
            EXPECT_EQ(logged[i].detail, i);
        }
    }
    const LaunchReport& report = ctx.last_launch();
    ASSERT_EQ(report.exceptions.count(kUserExceptionBase + 7), 1u) << report.summary();
    EXPECT_EQ(report.exceptions.at(kUserExceptionBase + 7).count, 3u);
    EXPECT_EQ(report.exceptions.at(kUserExceptionBase + 7).first_index.x, 1u);
}

TEST_F(DeferredRaysTest, FromAHitProgramTheRayIsTracedAtOnce) {
    auto onward = ctx.create_buffer<TestPayload>(BufferType::kOutput, 8);
    auto first = ctx.create_material();
    first->set_closest_hit(0, program(ctx, LUCENT_PROGRAM(deferred_onward_hit)));
    (*first)["onward"] = onward;
    auto near = make_instance(ctx, make_triangles(ctx, square_at(4.0f)), first);
    auto far =
        make_instance(ctx, make_triangles(ctx, square_at(9.0f, -2, 2, -2, 2)),
                      make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 5));
    auto top = make_geometry_group(ctx, {near, far});
    std::vector<CastRay> rays;
    for (int i = 0; i < 8; ++i)
        rays.push_back(cast_ray(make_float3(float(i) - 0.5f, 0, 0), make_float3(0, 0, 1)));
    // In the context's scope: a variable of `first` holding the group that holds `first`
    // would be a cycle of shared pointers, never freed.
    ctx["top"] = top;
    const auto payloads = cast(LUCENT_PROGRAM(deferred_cast), top, rays);
    const auto second = read_buffer<TestPayload>(*onward);
    for (unsigned i = 0; i < 8; ++i) {
        EXPECT_FLOAT_EQ(payloads[i].t, 4.0f) << "index " << i;
        const bool behind_far = rays[i].origin.x > -2 && rays[i].origin.x < 2;
        EXPECT_EQ(second[i].hit, behind_far ? 1 : 0) << "index " << i;
        EXPECT_EQ(payloads[i].anyhit_count, behind_far ? 1u : 0u)
            << "the onward ray's answer is there when trace_deferred() returns";
        if (behind_far) {
            EXPECT_FLOAT_EQ(second[i].t, 5.0f) << "index " << i;
        }
    }
}

TEST_F(DeferredRaysTest, APayloadInTheProgramsFrameIsRefused) {
    if (test_backend() != BackendKind::kCpu)
        GTEST_SKIP() << "the GPU traces the ray at once, while the local still exists";
    auto top = clutter_group();
    expect_error([&] { cast(LUCENT_PROGRAM(deferred_cast_into_local), top, rays_down(10)); },
                 {"trace_deferred()", "local variable", "buffer"});
}

}  // namespace

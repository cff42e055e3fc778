// The device API's rules (one trace state machine, src/runtime/, for both backends): what
// each program kind sees and may call, the interval rules of potential_intersection, any-hit
// programs ending at ignore_intersection() and terminate_ray(), and the exceptions of a bad
// trace. Runs on the CPU; LUCENT_TEST_BACKEND=cuda runs the same cases on the GPU, and
// LUCENT_TEST_JIT_CHECK=90 compiles each case's megakernel for sm_90 on the way.
#include "tests/programs/device_api_programs.h"
#include "tests/test_support.h"

namespace lucent_tests {
namespace {

// ---- what each program kind sees ----------------------------------------------------------

/// Launch indices of the probe scene and what each does.
enum ProbeRay : unsigned {
    kSphereRay,    // hits the sphere below Selector → Transform(+2, 0, 0): visit, intersection,
                   // any-hit and closest hit run
    kMissRay,      // goes the other way: miss runs
    kThrowRay,     // misses, then its ray generation raises: the exception program runs
    kTriangleRay,  // hits the triangle below Transform(-3, 0, 0), no any-hit: its attribute
                   // program runs at shade time
    kProbeRays,
};

class ProbeScene {
  public:
    explicit ProbeScene(const ContextOptions& options = test_context_options()) : ctx(options) {
        ctx.set_entry_point_count(1);
        ctx.set_ray_type<ProbePayload>(0, "probe");
        ctx.set_exception_enabled(kAllExceptions, true);
        ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(da_probe_cast)));
        ctx.set_exception_program(0, program(ctx, LUCENT_PROGRAM(da_probe_exception)));
        ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(da_probe_miss)));

        auto sphere = make_spheres(ctx, {make_float4(0, 0, 0, 1)});
        sphere->set_intersection_program(program(ctx, LUCENT_PROGRAM(da_probe_sphere_intersect)));
        auto sphere_material =
            make_material(ctx, program(ctx, LUCENT_PROGRAM(da_probe_sphere_hit)), 0);
        sphere_material->set_any_hit(0, program(ctx, LUCENT_PROGRAM(da_probe_any_hit)));
        auto selector = ctx.create_selector();
        selector->set_visit_program(program(ctx, LUCENT_PROGRAM(da_probe_visit)));
        selector->add_child(
            transform(translation(2, 0, 0),
                      make_geometry_group(ctx, {make_instance(ctx, sphere, sphere_material)})));

        auto triangle = make_triangles(
            ctx, {make_float3(-1, -1, 0), make_float3(1, -1, 0), make_float3(0, 1, 0)});
        triangle->set_attribute_program(program(ctx, LUCENT_PROGRAM(da_probe_attribute)));
        auto triangle_group = make_geometry_group(
            ctx, {make_instance(
                     ctx, triangle,
                     make_material(ctx, program(ctx, LUCENT_PROGRAM(da_probe_triangle_hit)), 0))});

        auto top = ctx.create_group();
        top->add_child(selector);
        top->add_child(transform(translation(-3, 0, 0), triangle_group));
        ctx["top"] = top;
        ctx["throw_at"] = unsigned(kThrowRay);
        ctx["rays"] =
            input_buffer(ctx, std::vector<CastRay>{
                                  cast_ray(make_float3(2, 0, -5), make_float3(0, 0, 1)),
                                  cast_ray(make_float3(2, 0, -5), make_float3(0, 0, -1)),
                                  cast_ray(make_float3(2, 0, -5), make_float3(0, 0, -1)),
                                  cast_ray(make_float3(-3, 0.1f, -5), make_float3(0, 0, 1)),
                              });
        probes = ctx.create_buffer<Probe>(BufferType::kInputOutput, kProbeRays * kProbeSlots);
        probes->upload(std::vector<Probe>(kProbeRays * kProbeSlots, Probe{}));
        ctx["probes"] = probes;
    }

    std::vector<Probe> run() {
        ctx.launch(0, kProbeRays);
        return read_buffer<Probe>(*probes);
    }

    std::shared_ptr<Transform> transform(const Matrix4x3& m, std::shared_ptr<Node> child) {
        auto t = ctx.create_transform();
        t->set_matrix(m);
        t->set_child(std::move(child));
        return t;
    }

    Context ctx;
    std::shared_ptr<Buffer> probes;
};

/// One program kind on one ray: what it must see.
struct KindCase {
    const char* name;
    ProbeSlot slot;
    ProbeRay ray;
    float3 origin;         // current_ray().origin
    float3 direction;      // current_ray().direction
    float t;               // t_hit()
    bool check_prim;       // primitive_index() is defined here: 0
    bool may_report;       // potential/report_intersection may succeed (intersection only)
    float3 world_of_zero;  // object_to_world_point(0): the transform in effect
};

std::ostream& operator<<(std::ostream& os, const KindCase& c) {
    return os << c.name;
}

const float3 kZero = make_float3(0, 0, 0);
const float3 kForward = make_float3(0, 0, 1), kBackward = make_float3(0, 0, -1);

class DeviceApiKindTest : public testing::TestWithParam<KindCase> {};

TEST_P(DeviceApiKindTest, SeesItsRayHitAndTransformAndMayCallOnlyItsOwnFunctions) {
    const KindCase& c = GetParam();
    ProbeScene scene;
    const std::vector<Probe> probes = scene.run();
    const Probe& p = probes[c.ray * kProbeSlots + c.slot];
    ASSERT_EQ(p.ran, 1u) << c.name << " did not run";
    EXPECT_FLOAT3_NEAR(p.ray_origin, c.origin, kEps);
    EXPECT_FLOAT3_NEAR(p.ray_direction, c.direction, kEps);
    EXPECT_NEAR(p.t, c.t, kEps) << "t_hit()";
    if (c.check_prim) EXPECT_EQ(p.prim, 0u) << "primitive_index()";
    EXPECT_FLOAT3_NEAR(p.world_of_zero, c.world_of_zero, kEps);
    if (c.may_report) {
        EXPECT_EQ(p.potential, 1u) << "the sphere's entry point is inside the interval";
        EXPECT_EQ(p.reported, 1u) << "and is committed";
    } else {
        EXPECT_EQ(p.potential, 0u) << "potential_intersection() outside an intersection program";
        EXPECT_EQ(p.reported, 0u) << "report_intersection() outside an intersection program";
    }
}

INSTANTIATE_TEST_SUITE_P(
    EveryProgramKind, DeviceApiKindTest,
    testing::Values(
        // Outside any trace: a zero ray, t 0, no transform.
        KindCase{"RayGeneration", kProbeRayGeneration, kSphereRay, kZero, kZero, 0, true, false,
                 kZero},
        KindCase{"Exception", kProbeException, kThrowRay, kZero, kZero, 0, true, false, kZero},
        // Miss: the world ray, t = tmax.
        KindCase{"Miss", kProbeMiss, kMissRay, make_float3(2, 0, -5), kBackward, 100, false, false,
                 kZero},
        // The selector is above the Transform: its visit program sees world space.
        KindCase{"Visit", kProbeVisit, kSphereRay, make_float3(2, 0, -5), kForward, 100, false,
                 false, kZero},
        // Below Transform(+2, 0, 0): object space, the traversal position's transform.
        KindCase{"Intersection", kProbeIntersection, kSphereRay, make_float3(0, 0, -5), kForward,
                 100, true, true, make_float3(2, 0, 0)},
        KindCase{"AnyHit", kProbeAnyHit, kSphereRay, make_float3(0, 0, -5), kForward, 4, true,
                 false, make_float3(2, 0, 0)},
        // Closest hit: the world ray, the committed hit's t, primitive and transform.
        KindCase{"ClosestHit", kProbeClosestHit, kSphereRay, make_float3(2, 0, -5), kForward, 4,
                 true, false, make_float3(2, 0, 0)},
        // The attribute program runs at shade time as at the hit: object space below
        // Transform(-3, 0, 0), the committed t.
        KindCase{"Attribute", kProbeAttribute, kTriangleRay, make_float3(0, 0.1f, -5), kForward, 5,
                 true, false, make_float3(-3, 0, 0)},
        KindCase{"ClosestHitOfATriangle", kProbeClosestHit, kTriangleRay, make_float3(-3, 0.1f, -5),
                 kForward, 5, true, false, make_float3(-3, 0, 0)}),
    [](const testing::TestParamInfo<KindCase>& info) { return std::string(info.param.name); });

TEST(DeviceApiProbeScene, EachRayEndsInTheProgramItShould) {
    ProbeScene scene;
    const std::vector<Probe> probes = scene.run();
    auto ran = [&](ProbeRay ray, ProbeSlot slot) { return probes[ray * kProbeSlots + slot].ran; };
    EXPECT_EQ(ran(kSphereRay, kProbeMiss), 0u);
    EXPECT_EQ(ran(kMissRay, kProbeClosestHit), 0u);
    EXPECT_EQ(ran(kTriangleRay, kProbeAnyHit), 0u) << "the triangle's material has no any-hit";
    EXPECT_EQ(ran(kSphereRay, kProbeException), 0u);
    EXPECT_EQ(scene.ctx.last_launch().exception_count(), 1u) << scene.ctx.last_launch().summary();
}

// ---- the interval of potential_intersection --------------------------------------------------

TEST(DeviceApiInterval, PotentialIntersectionIsTheOpenIntervalUpToTheClosestHit) {
    Context ctx(test_context_options());
    ctx.set_entry_point_count(1);
    ctx.set_ray_type<TestPayload>(0, "radiance");
    ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(common_miss)));
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(common_cast)));
    auto geometry = make_spheres(ctx, {make_float4(0, 0, 0, 1)});  // its box: the bounds
    geometry->set_intersection_program(program(ctx, LUCENT_PROGRAM(da_interval_intersect)));
    ctx["top"] = make_geometry_group(
        ctx,
        {make_instance(ctx, geometry,
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 1))});
    // common_cast traces (tmin 1e-4, tmax kInfinity) from z = -5; the commit is at t = 3.
    const std::vector<float> ts = {-1.0f,  0.0f,   1e-4f, 2.0f,     3.0f,
                                   2.999f, 3.001f, 1e20f, kInfinity};
    const std::vector<unsigned> before = {0, 0, 0, 1, 1, 1, 1, 1, 0};
    const std::vector<unsigned> after = {0, 0, 0, 1, 0, 1, 0, 0, 0};
    ctx["ts"] = input_buffer(ctx, ts);
    auto before_buffer = ctx.create_buffer<unsigned>(BufferType::kOutput, unsigned(ts.size()));
    auto after_buffer = ctx.create_buffer<unsigned>(BufferType::kOutput, unsigned(ts.size()));
    auto stale = ctx.create_buffer<unsigned>(BufferType::kOutput, 2);
    ctx["before"] = before_buffer;
    ctx["after"] = after_buffer;
    ctx["stale"] = stale;
    ctx["commit_t"] = 3.0f;
    ctx["rays"] =
        input_buffer(ctx, std::vector<CastRay>{cast_ray(make_float3(0, 0, -5), kForward)});
    auto results = ctx.create_buffer<TestPayload>(BufferType::kOutput, 1);
    ctx["results"] = results;
    ctx.launch(0, 1);
    const auto got_before = read_buffer<unsigned>(*before_buffer);
    const auto got_after = read_buffer<unsigned>(*after_buffer);
    for (size_t i = 0; i < ts.size(); ++i) {
        EXPECT_EQ(got_before[i], before[i]) << "before the commit, t = " << ts[i];
        EXPECT_EQ(got_after[i], after[i]) << "after the commit at 3, t = " << ts[i];
    }
    EXPECT_EQ(read_buffer<unsigned>(*stale)[0], 0u)
        << "a false potential_intersection closes the candidate an earlier one opened";
    EXPECT_EQ(read_buffer<unsigned>(*stale)[1], 0u) << "a reported candidate is closed";
    const TestPayload hit = read_buffer<TestPayload>(*results)[0];
    EXPECT_EQ(hit.hit, 1);
    EXPECT_NEAR(hit.t, 3.0f, kEps);
}

// ---- any-hit programs end at ignore_intersection() and terminate_ray() ------------------------

struct EndCase {
    const char* name;
    const ProgramDesc& (*any_hit)();
    float ignore_before;
    int hit;           // the ray's end: 0 miss, 1 closest hit
    float hit_t;       // closest hit's t_hit()
    bool exact;        // calls and reached are exact; else at least (traversal order)
    unsigned calls;    // any-hit invocations
    unsigned reached;  // statements after a condition that did not end the program
};

std::ostream& operator<<(std::ostream& os, const EndCase& c) {
    return os << c.name;
}

class AnyHitEndTest : public testing::TestWithParam<EndCase> {};

/// Traces one ray through three squares whose material has `c`'s any-hit program.
EndPayload run_end_case(const EndCase& c, const ContextOptions& options) {
    Context ctx(options);
    ctx.set_entry_point_count(1);
    ctx.set_ray_type<EndPayload>(0, "end");
    ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(da_end_miss)));
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(da_end_cast)));
    auto material = make_material(ctx, program(ctx, LUCENT_PROGRAM(da_end_hit)), 0);
    material->set_any_hit(0, program(ctx, c.any_hit()));
    (*material)["ignore_before"] = c.ignore_before;
    // Three squares across the ray, at t = 6, 7 and 8 from z = -5.
    std::vector<float3> squares;
    for (float z : {1.0f, 2.0f, 3.0f})
        for (const float3& v : square_at(z)) squares.push_back(v);
    ctx["top"] =
        make_geometry_group(ctx, {make_instance(ctx, make_triangles(ctx, squares), material)});
    ctx["rays"] =
        input_buffer(ctx, std::vector<CastRay>{cast_ray(make_float3(0.1f, 0.2f, -5), kForward)});
    auto results = ctx.create_buffer<EndPayload>(BufferType::kOutput, 1);
    ctx["results"] = results;
    ctx.launch(0, 1);
    return read_buffer<EndPayload>(*results)[0];
}

TEST_P(AnyHitEndTest, CodeAfterTheEndDoesNotRun) {
    const EndCase& c = GetParam();
    const EndPayload r = run_end_case(c, test_context_options());
    EXPECT_EQ(r.after, 0u) << "a statement after ignore_intersection()/terminate_ray() ran";
    EXPECT_EQ(r.hit, c.hit);
    if (c.hit == 1 && c.hit_t > 0)
        EXPECT_NEAR(r.hit_t, c.hit_t, kEps) << "closest hit runs on the accepted hit";
    if (c.hit == 1 && c.hit_t < 0)
        EXPECT_GT(r.hit_t, std::max(c.ignore_before, 5.9f))
            << "closest hit runs on an accepted square";
    if (c.exact) {
        EXPECT_EQ(r.calls, c.calls) << "any-hit invocations";
        EXPECT_EQ(r.reached, c.reached);
    } else {
        EXPECT_GE(r.calls, c.calls) << "any-hit invocations";
        EXPECT_GE(r.reached, c.reached);
    }
}

INSTANTIATE_TEST_SUITE_P(
    IgnoreAndTerminate, AnyHitEndTest,
    testing::Values(
        // Every candidate ignored: all three are offered, the ray misses.
        EndCase{"IgnoreEndsTheProgram",
                []() -> const ProgramDesc& { return LUCENT_PROGRAM(da_ignore_then_write); }, 0, 0,
                0, true, 3, 0},
        // The first candidate found accepted and traversal stopped; closest hit still runs.
        EndCase{"TerminateEndsTheProgramAndStillRunsClosestHit",
                []() -> const ProgramDesc& { return LUCENT_PROGRAM(da_terminate_then_write); }, 0,
                1, -1, true, 1, 0},
        // A conditional ignore ends only the calls it is made in: the squares at 7 and 8 pass
        // it, and the nearer of them is the closest hit.
        EndCase{"ConditionalIgnoreEndsOnlyWhenCalled",
                []() -> const ProgramDesc& { return LUCENT_PROGRAM(da_ignore_near); }, 6.5f, 1, 7,
                false, 2, 1},
        // Ignore near, terminate far: the ray stops at a square beyond 6.5.
        EndCase{"IgnoreOrTerminateInBranches",
                []() -> const ProgramDesc& { return LUCENT_PROGRAM(da_terminate_far); }, 6.5f, 1,
                -1, false, 1, 0}),
    [](const testing::TestParamInfo<EndCase>& info) { return std::string(info.param.name); });

// ---- exceptions of a bad trace: the same outcome on both backends ------------------------------

struct BadTraceCase {
    const char* name;
    unsigned mode;  // da_bad_trace's
    int code;
    unsigned detail;
};

std::ostream& operator<<(std::ostream& os, const BadTraceCase& c) {
    return os << c.name;
}

class BadTraceExceptionTest : public testing::TestWithParam<BadTraceCase> {};

TEST_P(BadTraceExceptionTest, RaisesItsCodeWithItsDetailAndRunsTheExceptionProgram) {
    const BadTraceCase& c = GetParam();
    constexpr unsigned kIndices = 3;
    Context ctx(test_context_options());
    ctx.set_entry_point_count(1);
    ctx.set_ray_type<ProbePayload>(0, "probe");
    ctx.set_max_recursion_depth(1);
    ctx.set_exception_enabled(kAllExceptions, true);
    ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(da_bad_trace_miss)));
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(da_bad_trace)));
    ctx.set_exception_program(0, program(ctx, LUCENT_PROGRAM(da_log_exception)));
    auto sphere = make_spheres(ctx, {make_float4(0, 0, 0, 1)});
    if (c.code == kExceptionMaterialIndexOutOfRange)
        sphere->set_intersection_program(program(ctx, LUCENT_PROGRAM(da_sphere_material_3)));
    ctx["top"] = make_geometry_group(
        ctx, {make_instance(ctx, sphere,
                            make_material(ctx, program(ctx, LUCENT_PROGRAM(da_retrace)), 0))});
    ctx["mode"] = c.mode;
    auto finished = ctx.create_buffer<int>(BufferType::kInputOutput, kIndices);
    finished->upload(std::vector<int>(kIndices, 0));
    ctx["finished"] = finished;
    auto infos = ctx.create_buffer<ExceptionInfo>(BufferType::kInputOutput, kIndices);
    infos->upload(std::vector<ExceptionInfo>(kIndices, ExceptionInfo{0, {0, 0, 0}, 0}));
    ctx["infos"] = infos;
    ctx.launch(0, kIndices);

    const LaunchReport& report = ctx.last_launch();
    ASSERT_EQ(report.exceptions.count(c.code), 1u) << report.summary();
    EXPECT_EQ(report.exceptions.at(c.code).count, kIndices);
    EXPECT_EQ(report.exception_count(), kIndices) << report.summary();
    const auto logged = read_buffer<ExceptionInfo>(*infos);
    for (unsigned i = 0; i < kIndices; ++i) {
        EXPECT_EQ(logged[i].code, c.code) << "index " << i;
        EXPECT_EQ(logged[i].detail, c.detail) << "index " << i;
        EXPECT_EQ(logged[i].launch_index.x, i);
    }
    // The CPU unwinds the launch index; the GPU lets its ray generation run on with traces
    // disabled (docs/programming-model.md).
    if (test_backend() == BackendKind::kCpu)
        for (int f : read_buffer<int>(*finished)) EXPECT_EQ(f, 0);
}

INSTANTIATE_TEST_SUITE_P(
    EveryCheck, BadTraceExceptionTest,
    testing::Values(BadTraceCase{"InvalidRayType", 0, kExceptionInvalidRayType, 9},
                    BadTraceCase{"PayloadTypeMismatch", 1, kExceptionPayloadTypeMismatch, 0},
                    BadTraceCase{"InvalidHandle", 2, kExceptionInvalidHandle, 9999},
                    BadTraceCase{"StackOverflow", 3, kExceptionStackOverflow, 2},
                    BadTraceCase{"MaterialIndexOutOfRange", 4, kExceptionMaterialIndexOutOfRange,
                                 3}),
    [](const testing::TestParamInfo<BadTraceCase>& info) { return std::string(info.param.name); });

// ---- the same scenes as megakernels ---------------------------------------------------------

/// On the CPU, the probe scene (selector, transforms, custom and triangle geometry, attribute,
/// any-hit and exception programs) and the any-hit scenes also compile as CUDA megakernels
/// for sm_90 (no GPU needed); a failed compile throws from the launch.
TEST(DeviceApiJit, TheSuitesScenesCompileAsMegakernelsForSm90) {
#if !LUCENT_HAVE_CUDA
    GTEST_SKIP() << "built without the CUDA toolkit: no megakernel to compile";
#else
    if (test_backend() != BackendKind::kCpu) GTEST_SKIP() << "the GPU compiles them to launch";
    ContextOptions options = test_context_options();
    options.jit_check_sm = 90;
    ProbeScene scene(options);
    const std::vector<Probe> probes = scene.run();
    EXPECT_EQ(probes[kSphereRay * kProbeSlots + kProbeAnyHit].ran, 1u);
    const EndCase terminate_far{
        "IgnoreOrTerminateInBranches",
        []() -> const ProgramDesc& { return LUCENT_PROGRAM(da_terminate_far); },
        6.5f,
        1,
        -1,
        false,
        1,
        0};
    EXPECT_EQ(run_end_case(terminate_far, options).after, 0u);
#endif
}

}  // namespace
}  // namespace lucent_tests

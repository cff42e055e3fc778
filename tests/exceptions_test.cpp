// Exceptions (OptiX paper §3.1): stack overflow, out-of-bounds buffer access, user
// exceptions; what the exception program receives and what LaunchReport summarises.
#include "tests/programs/exception_programs.h"
#include "tests/test_support.h"

namespace lucent_tests {
namespace {

using testing::HasSubstr;

constexpr unsigned kNotRaised = 0;  // ExceptionInfo::code of a slot no exception wrote

class ExceptionsTest : public testing::Test {
  protected:
    ExceptionsTest() : ctx(test_context_options()) {
        ctx.set_entry_point_count(1);
        ctx.set_ray_type<TestPayload>(0, "radiance");
        ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(common_miss)));
        ctx.set_exception_program(0, program(ctx, LUCENT_PROGRAM(et_log_exception)));
    }

    /// A launch-sized exception log, cleared so untouched slots read code 0.
    std::shared_ptr<Buffer> exception_log(unsigned count) {
        auto infos = ctx.create_buffer<ExceptionInfo>(BufferType::kInputOutput, count);
        infos->upload(std::vector<ExceptionInfo>(count, ExceptionInfo{0, {0, 0, 0}, 0}));
        ctx["infos"] = infos;
        return infos;
    }

    /// A mirror at z = 1 whose closest hit re-traces until `wanted_depth`.
    void recursion_scene(int wanted_depth) {
        auto material = ctx.create_material();
        material->set_closest_hit(0, program(ctx, LUCENT_PROGRAM(et_recurse)));
        auto top = make_geometry_group(
            ctx, {make_instance(ctx, make_triangles(ctx, square_at(1)), material)});
        ctx["top"] = top;
        ctx["wanted_depth"] = wanted_depth;
        ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(et_trace_depth)));
    }

    std::shared_ptr<Buffer> depth_buffer(unsigned count) {
        auto depths = ctx.create_buffer<int>(BufferType::kInputOutput, count);
        depths->upload(std::vector<int>(count, -7));  // -7: the ray generation never finished
        ctx["depths"] = depths;
        return depths;
    }

    Context ctx;
};

// ---- stack overflow ------------------------------------------------------------------

TEST_F(ExceptionsTest, RecursionWithinTheMaximumDepthRaisesNothing) {
    recursion_scene(4);
    ctx.set_max_recursion_depth(4);
    ctx.set_exception_enabled(kExceptionStackOverflow, true);
    auto depths = depth_buffer(8);
    exception_log(8);
    ctx.launch(0, 8);
    EXPECT_EQ(ctx.last_launch().exception_count(), 0u) << ctx.last_launch().summary();
    for (int d : read_buffer<int>(*depths)) EXPECT_EQ(d, 4);
}

TEST_F(ExceptionsTest, RecursionBeyondTheMaximumDepthRaisesStackOverflow) {
    recursion_scene(5);
    ctx.set_max_recursion_depth(4);
    ctx.set_exception_enabled(kExceptionStackOverflow, true);
    EXPECT_TRUE(ctx.exception_enabled(kExceptionStackOverflow));
    auto depths = depth_buffer(8);
    auto infos = exception_log(8);
    ctx.launch(0, 8);

    const LaunchReport& report = ctx.last_launch();
    ASSERT_EQ(report.exceptions.count(kExceptionStackOverflow), 1u) << report.summary();
    EXPECT_EQ(report.exceptions.at(kExceptionStackOverflow).count, 8u);
    EXPECT_EQ(report.exceptions.at(kExceptionStackOverflow).first_index.x, 0u);
    EXPECT_EQ(report.exception_count(), 8u);
    const auto logged = read_buffer<ExceptionInfo>(*infos);
    for (unsigned i = 0; i < 8; ++i) {
        EXPECT_EQ(logged[i].code, kExceptionStackOverflow) << "index " << i;
        EXPECT_EQ(logged[i].launch_index.x, i);
    }
    // CPU backend: the exception unwinds the launch index, so the ray generation never
    // stored its depth (the GPU backend instead lets it run on with traces disabled).
    if (test_backend() == BackendKind::kCpu)
        for (int d : read_buffer<int>(*depths)) EXPECT_EQ(d, -7);
}

// ---- buffer index out of bounds ---------------------------------------------------------

TEST_F(ExceptionsTest, OutOfBoundsReadIsReportedWithTheIndexWhenEnabled) {
    ctx.set_exception_enabled(kExceptionBufferIndexOutOfBounds, true);
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(et_read_1d)));
    ctx["input"] = input_buffer(ctx, std::vector<float>{1, 2, 3, 4});
    auto output = ctx.create_buffer<float>(BufferType::kOutput, 8);
    ctx["output"] = output;
    auto infos = exception_log(8);
    ctx.launch(0, 8);

    const LaunchReport& report = ctx.last_launch();
    ASSERT_EQ(report.exceptions.count(kExceptionBufferIndexOutOfBounds), 1u) << report.summary();
    const auto& summary = report.exceptions.at(kExceptionBufferIndexOutOfBounds);
    EXPECT_EQ(summary.count, 4u) << "indices 4..7 read past the 4-element input";
    EXPECT_EQ(summary.first_index.x, 4u);
    const auto logged = read_buffer<ExceptionInfo>(*infos);
    const auto values = read_buffer<float>(*output);
    for (unsigned i = 0; i < 8; ++i) {
        if (i < 4) {
            EXPECT_EQ(logged[i].code, int(kNotRaised)) << "index " << i;
            EXPECT_EQ(values[i], 2.0f * float(i + 1));
        } else {
            EXPECT_EQ(logged[i].code, kExceptionBufferIndexOutOfBounds) << "index " << i;
            EXPECT_EQ(logged[i].detail, i) << "detail is the offending index";
        }
    }
}

TEST_F(ExceptionsTest, OutOfBoundsTwoDimensionalReadReportsTheLinearIndex) {
    ctx.set_exception_enabled(kAllExceptions, true);
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(et_read_2d)));
    auto input = ctx.create_buffer<float>(BufferType::kInput, 3, 3);
    input->upload(std::vector<float>(9, 1.0f));
    ctx["input2d"] = input;
    ctx["output2d"] = ctx.create_buffer<float>(BufferType::kOutput, 4, 4);
    auto infos = exception_log(16);
    ctx.launch(0, 4, 4);

    const LaunchReport& report = ctx.last_launch();
    ASSERT_EQ(report.exceptions.count(kExceptionBufferIndexOutOfBounds), 1u) << report.summary();
    const auto& summary = report.exceptions.at(kExceptionBufferIndexOutOfBounds);
    EXPECT_EQ(summary.count, 7u) << "the column x = 3 and the row y = 3";
    EXPECT_EQ(summary.first_index.x, 3u);
    EXPECT_EQ(summary.first_index.y, 0u);
    const auto logged = read_buffer<ExceptionInfo>(*infos);
    // (3, 1): the detail is the index the view computed, y * width + x = 1 * 3 + 3.
    EXPECT_EQ(logged[1 * 4 + 3].code, kExceptionBufferIndexOutOfBounds);
    EXPECT_EQ(logged[1 * 4 + 3].detail, 6u);
    EXPECT_EQ(logged[1 * 4 + 3].launch_index.y, 1u);
}

TEST_F(ExceptionsTest, OutOfBoundsWriteIsReportedWhenEnabled) {
    ctx.set_exception_enabled(kExceptionBufferIndexOutOfBounds, true);
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(et_write_past_end)));
    ctx["output"] = ctx.create_buffer<float>(BufferType::kOutput, 5);
    exception_log(5);
    ctx.launch(0, 5);
    const LaunchReport& report = ctx.last_launch();
    ASSERT_EQ(report.exceptions.count(kExceptionBufferIndexOutOfBounds), 1u) << report.summary();
    EXPECT_EQ(report.exceptions.at(kExceptionBufferIndexOutOfBounds).count, 1u);
    EXPECT_EQ(report.exceptions.at(kExceptionBufferIndexOutOfBounds).first_index.x, 4u);
}

TEST_F(ExceptionsTest, InBoundsReadsReportNothingWithExceptionsOff) {
    // Exceptions are off by default; nothing here reads out of bounds (reading past the end
    // with checks off would be undefined behaviour, not something to test).
    EXPECT_FALSE(ctx.exception_enabled(kExceptionBufferIndexOutOfBounds));
    EXPECT_FALSE(ctx.exception_enabled(kExceptionStackOverflow));
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(et_read_1d)));
    ctx["input"] = input_buffer(ctx, std::vector<float>{1, 2, 3, 4});
    auto output = ctx.create_buffer<float>(BufferType::kOutput, 4);
    ctx["output"] = output;
    exception_log(4);
    ctx.launch(0, 4);
    EXPECT_EQ(ctx.last_launch().exception_count(), 0u);
    EXPECT_TRUE(ctx.last_launch().exceptions.empty());
    EXPECT_EQ(read_buffer<float>(*output), (std::vector<float>{2, 4, 6, 8}));
}

TEST_F(ExceptionsTest, DisablingACodeAgainTurnsItOff) {
    ctx.set_exception_enabled(kAllExceptions, true);
    EXPECT_TRUE(ctx.exception_enabled(kExceptionBufferIndexOutOfBounds));
    ctx.set_exception_enabled(kExceptionBufferIndexOutOfBounds, false);
    EXPECT_FALSE(ctx.exception_enabled(kExceptionBufferIndexOutOfBounds));
    EXPECT_TRUE(ctx.exception_enabled(kExceptionStackOverflow));
}

// ---- exceptions below the ray generation program -------------------------------------

TEST_F(ExceptionsTest, UserExceptionInAClosestHitReportsTheLaunchIndex) {
    ctx.set_exception_enabled(kAllExceptions, true);
    auto material = ctx.create_material();
    material->set_closest_hit(0, program(ctx, LUCENT_PROGRAM(et_throw_in_hit)));
    ctx["top"] =
        make_geometry_group(ctx, {make_instance(ctx, make_triangles(ctx, square_at(1)), material)});
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(et_trace_depth)));
    auto depths = depth_buffer(6);
    auto infos = exception_log(6);
    ctx.launch(0, 6);
    const auto logged = read_buffer<ExceptionInfo>(*infos);
    const auto finished = read_buffer<int>(*depths);
    for (unsigned i = 0; i < 6; ++i) {
        if (i % 2 == 0) {
            EXPECT_EQ(logged[i].code, int(kNotRaised)) << "index " << i;
            EXPECT_EQ(finished[i], 1) << "index " << i;
        } else {
            EXPECT_EQ(logged[i].code, kCodeA) << "index " << i;
            EXPECT_EQ(logged[i].detail, 99u);
            EXPECT_EQ(logged[i].launch_index.x, i);
            // CPU backend: the exception unwinds the ray generation program too. A GPU
            // cannot unwind: later traces return at once and the program runs to its end.
            if (test_backend() == BackendKind::kCpu) EXPECT_EQ(finished[i], -7) << "index " << i;
        }
    }
    ASSERT_EQ(ctx.last_launch().exceptions.count(kCodeA), 1u);
    EXPECT_EQ(ctx.last_launch().exceptions.at(kCodeA).count, 3u);
    EXPECT_EQ(ctx.last_launch().exceptions.at(kCodeA).first_index.x, 1u);
}

class BadTraceTest : public ExceptionsTest {
  protected:
    /// Runs et_bad_trace in `mode` over 3 indices; returns the report.
    const LaunchReport& run(int mode) {
        ctx.set_exception_enabled(kAllExceptions, true);
        ctx["top"] = make_geometry_group(
            ctx, {make_instance(
                     ctx, make_triangles(ctx, square_at(1)),
                     make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1))});
        ctx["mode"] = mode;
        ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(et_bad_trace)));
        infos = exception_log(3);
        ctx.launch(0, 3);
        return ctx.last_launch();
    }
    std::shared_ptr<Buffer> infos;
};

TEST_F(BadTraceTest, TraceWithAnotherPayloadTypeRaisesPayloadTypeMismatch) {
    const LaunchReport& report = run(0);
    ASSERT_EQ(report.exceptions.count(kExceptionPayloadTypeMismatch), 1u) << report.summary();
    EXPECT_EQ(report.exceptions.at(kExceptionPayloadTypeMismatch).count, 3u);
    EXPECT_EQ(read_buffer<ExceptionInfo>(*infos)[2].code, kExceptionPayloadTypeMismatch);
}

TEST_F(BadTraceTest, TraceAgainstAnInvalidHandleRaisesInvalidHandle) {
    const LaunchReport& report = run(1);
    ASSERT_EQ(report.exceptions.count(kExceptionInvalidHandle), 1u) << report.summary();
    EXPECT_EQ(report.exceptions.at(kExceptionInvalidHandle).count, 3u);
}

TEST_F(BadTraceTest, TraceWithAnUndeclaredRayTypeRaisesInvalidRayType) {
    const LaunchReport& report = run(2);
    ASSERT_EQ(report.exceptions.count(kExceptionInvalidRayType), 1u) << report.summary();
    EXPECT_EQ(report.exceptions.at(kExceptionInvalidRayType).count, 3u);
    EXPECT_EQ(read_buffer<ExceptionInfo>(*infos)[0].detail, 9u) << "detail: the ray type";
}

TEST_F(ExceptionsTest, ReportedMaterialIndexBeyondTheInstanceRaisesMaterialIndexOutOfRange) {
    ctx.set_exception_enabled(kAllExceptions, true);
    auto geometry = make_spheres(ctx, {make_float4(0.3f, 0.1f, 5, 1)});
    geometry->set_intersection_program(program(ctx, LUCENT_PROGRAM(et_sphere_bad_material)));
    ctx["top"] = make_geometry_group(
        ctx,
        {make_instance(ctx, geometry,
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 1))});
    ctx["wanted_depth"] = 1;
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(et_trace_depth)));
    depth_buffer(2);
    auto infos = exception_log(2);
    ctx.launch(0, 2);
    const LaunchReport& report = ctx.last_launch();
    ASSERT_EQ(report.exceptions.count(kExceptionMaterialIndexOutOfRange), 1u) << report.summary();
    EXPECT_EQ(report.exceptions.at(kExceptionMaterialIndexOutOfRange).count, 2u);
    EXPECT_EQ(read_buffer<ExceptionInfo>(*infos)[1].detail, 3u) << "detail: the material index";
}

TEST_F(ExceptionsTest, WideLaunchReportsExactCountsAndTheSmallestFirstIndex) {
    // Exceptions raised on every worker thread and tile must merge exactly.
    constexpr unsigned kW = 160, kH = 90;
    ctx.set_exception_enabled(kAllExceptions, true);
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(et_throw_pattern)));
    exception_log(kW * kH);
    uint64_t expected = 0;
    uint3 first{0, 0, 0};
    for (unsigned y = 0; y < kH; ++y)
        for (unsigned x = 0; x < kW; ++x)
            if ((7u * x + 13u * y) % 101u == 5u && expected++ == 0) first = uint3{x, y, 0};
    for (int repeat = 0; repeat < 3; ++repeat) {
        ctx.launch(0, kW, kH);
        const LaunchReport& report = ctx.last_launch();
        ASSERT_EQ(report.exceptions.count(kCodeA), 1u) << report.summary();
        EXPECT_EQ(report.exceptions.at(kCodeA).count, expected);
        EXPECT_EQ(report.exceptions.at(kCodeA).first_index.x, first.x);
        EXPECT_EQ(report.exceptions.at(kCodeA).first_index.y, first.y);
    }
}

TEST_F(ExceptionsTest, ExceptionProgramDoesNotRunForADisabledCode) {
    // Only stack overflow is on: a user exception must not reach the exception program.
    ctx.set_exception_enabled(kExceptionStackOverflow, true);
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(et_throw_pattern)));
    auto infos = exception_log(101);
    ctx.launch(0, 101);
    for (const ExceptionInfo& e : read_buffer<ExceptionInfo>(*infos))
        EXPECT_EQ(e.code, int(kNotRaised));
}

TEST_F(ExceptionsTest, OutOfBoundsReadInABoundingBoxProgramIsAnErrorOrReported) {
    // Three primitives but two spheres: the bounding-box program reads past the buffer
    // during the acceleration build, outside any launch index. With checks on, the host
    // must hear about it as a lucent::Error or in the report — never as a foreign
    // exception escaping launch().
    ctx.set_exception_enabled(kAllExceptions, true);
    auto geometry = make_spheres(ctx, {make_float4(0, 0, 5, 1), make_float4(3, 0, 5, 1)});
    geometry->set_primitive_count(3);
    ctx["top"] = make_geometry_group(
        ctx,
        {make_instance(ctx, geometry,
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 1))});
    ctx["wanted_depth"] = 1;
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(et_trace_depth)));
    depth_buffer(1);
    exception_log(1);
    try {
        ctx.launch(0, 1);
        EXPECT_EQ(ctx.last_launch().exceptions.count(kExceptionBufferIndexOutOfBounds), 1u)
            << "launch() returned, so the report must carry the out-of-bounds read: "
            << ctx.last_launch().summary();
    } catch (const Error& e) {
        EXPECT_TRUE(mentions_any(e.what(), {"bounding box", "common_sphere_bounds"})) << e.what();
    } catch (...) {
        ADD_FAILURE() << "a non-lucent::Error exception escaped Context::launch";
    }
}

// ---- user exceptions, the exception program, the report ------------------------------

class UserExceptionTest : public ExceptionsTest {
  protected:
    UserExceptionTest() {
        ctx.set_exception_enabled(kAllExceptions, true);
        ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(et_throw_some)));
        done = ctx.create_buffer<unsigned>(BufferType::kOutput, 4, 3);
        ctx["done"] = done;
        infos = exception_log(12);
    }
    std::shared_ptr<Buffer> done, infos;
};

TEST_F(UserExceptionTest, ExceptionProgramReceivesCodeLaunchIndexAndDetail) {
    ctx.launch(0, 4, 3);
    const auto logged = read_buffer<ExceptionInfo>(*infos);
    const auto finished = read_buffer<unsigned>(*done);
    for (unsigned y = 0; y < 3; ++y)
        for (unsigned x = 0; x < 4; ++x) {
            const ExceptionInfo& e = logged[y * 4 + x];
            SCOPED_TRACE(testing::Message() << "launch index (" << x << "," << y << ")");
            const bool a = (x == 2 && y == 1) || (x == 1 && y == 2), b = x == 3 && y == 0;
            if (!a && !b) {
                EXPECT_EQ(e.code, int(kNotRaised));
                EXPECT_EQ(finished[y * 4 + x], 1u);
                continue;
            }
            EXPECT_EQ(e.code, a ? kCodeA : kCodeB);
            EXPECT_EQ(e.launch_index.x, x);
            EXPECT_EQ(e.launch_index.y, y);
            EXPECT_EQ(e.launch_index.z, 0u);
            EXPECT_EQ(e.detail, 100u * x + y);
        }
}

TEST_F(UserExceptionTest, ReportCountsEachCodeWithItsFirstLaunchIndex) {
    ctx.launch(0, 4, 3);
    const LaunchReport& report = ctx.last_launch();
    EXPECT_EQ(report.exception_count(), 3u);
    ASSERT_EQ(report.exceptions.size(), 2u) << report.summary();
    ASSERT_EQ(report.exceptions.count(kCodeA), 1u);
    EXPECT_EQ(report.exceptions.at(kCodeA).count, 2u);
    // First = smallest linear index: (2,1) is 6, (1,2) is 9.
    EXPECT_EQ(report.exceptions.at(kCodeA).first_index.x, 2u);
    EXPECT_EQ(report.exceptions.at(kCodeA).first_index.y, 1u);
    ASSERT_EQ(report.exceptions.count(kCodeB), 1u);
    EXPECT_EQ(report.exceptions.at(kCodeB).count, 1u);
    EXPECT_EQ(report.exceptions.at(kCodeB).first_index.x, 3u);
    EXPECT_EQ(report.exceptions.at(kCodeB).first_index.y, 0u);
}

TEST_F(UserExceptionTest, ReportIsResetByTheNextLaunch) {
    ctx.launch(0, 4, 3);
    EXPECT_EQ(ctx.last_launch().exception_count(), 3u);
    // A 1x1 launch raises nothing: (0,0) is not one of the throwing indices.
    done->resize(1, 1);
    ctx.launch(0, 1, 1);
    EXPECT_EQ(ctx.last_launch().exception_count(), 0u) << ctx.last_launch().summary();
    EXPECT_TRUE(ctx.last_launch().exceptions.empty());
}

TEST_F(UserExceptionTest, ExceptionsAreCountedWithoutAnExceptionProgram) {
    ctx.set_exception_program(0, nullptr);
    ctx.launch(0, 4, 3);
    EXPECT_EQ(ctx.last_launch().exception_count(), 3u) << ctx.last_launch().summary();
}

TEST_F(UserExceptionTest, SummaryNamesEachExceptionWithCountAndFirstIndex) {
    ctx.launch(0, 4, 3);
    const std::string summary = ctx.last_launch().summary();
    EXPECT_THAT(summary, HasSubstr(exception_name(kCodeA)));
    EXPECT_THAT(summary, HasSubstr(exception_name(kCodeB)));
    EXPECT_THAT(summary, HasSubstr("2"));
    EXPECT_THAT(summary, HasSubstr("2,1,0")) << "first index of code A";
    EXPECT_THAT(summary, HasSubstr("3,0,0")) << "first index of code B";
}

TEST(ExceptionNameTest, NamesEngineAndUserCodes) {
    EXPECT_THAT(lowercase(exception_name(kExceptionStackOverflow)), HasSubstr("stack overflow"));
    EXPECT_THAT(lowercase(exception_name(kExceptionBufferIndexOutOfBounds)), HasSubstr("bounds"));
    EXPECT_THAT(lowercase(exception_name(kUserExceptionBase + 1)), HasSubstr("user exception"));
    EXPECT_THAT(lowercase(exception_name(kUserExceptionBase + 1)), HasSubstr("0x401"));
}

TEST_F(ExceptionsTest, StackOverflowSummaryNamesIt) {
    recursion_scene(3);
    ctx.set_max_recursion_depth(2);
    ctx.set_exception_enabled(kAllExceptions, true);
    depth_buffer(3);
    exception_log(3);
    ctx.launch(0, 3);
    const std::string summary = ctx.last_launch().summary();
    EXPECT_THAT(lowercase(summary), HasSubstr("stack overflow"));
    EXPECT_THAT(summary, HasSubstr("3"));
}

}  // namespace
}  // namespace lucent_tests

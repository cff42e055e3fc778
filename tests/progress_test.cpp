// Launch progress (ContextOptions::on_progress): on the CPU a launch reports bands of rows
// as they finish, and the rows it reports already hold their final values, so a viewer can
// show a slow frame as it renders.
#include "tests/programs/multi_device_programs.h"
#include "tests/test_support.h"

namespace lucent_tests {
namespace {

TEST(LaunchProgress, ReportsFinishedRowsThatAlreadyHoldTheirFinalValues) {
    const unsigned w = 37, h = 300;
    std::vector<unsigned> reported;
    std::vector<std::vector<float4>> seen;  // the image's finished rows when reported
    const Buffer* image_seen = nullptr;
    ContextOptions options;
    options.backend = BackendKind::kCpu;
    options.threads = 2;
    options.on_progress = [&](const LaunchProgress& p) {
        EXPECT_EQ(p.rows, h);
        EXPECT_EQ(p.size.x, w);
        ASSERT_EQ(p.outputs.size(), 1u);
        image_seen = p.outputs[0];
        reported.push_back(p.rows_done);
        const auto* pixels = static_cast<const float4*>(p.outputs[0]->raw());
        seen.emplace_back(pixels, pixels + size_t(p.rows_done) * w);
    };
    Context ctx(options);
    ctx.set_entry_point_count(1);
    ctx.set_ray_type<TestPayload>(0, "radiance");
    ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(common_miss)));
    auto hit = make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 1);
    ctx["top"] = make_geometry_group(
        ctx, {make_instance(ctx, make_spheres(ctx, {make_float4(0, 0, 0, 0.8f)}), hit)});
    auto image = ctx.create_buffer<float4>(BufferType::kOutput, w, h);
    ctx["image"] = image;
    ctx["dims"] = 2u;
    ctx["repeats"] = 1u;
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(md_pattern)));
    ctx.launch(0, w, h);

    ASSERT_GE(reported.size(), 2u) << "a 300-row launch comes in several bands";
    EXPECT_EQ(reported.back(), h);
    for (size_t i = 1; i < reported.size(); ++i) EXPECT_GT(reported[i], reported[i - 1]);
    EXPECT_EQ(image_seen, image.get());
    const auto final_image = read_buffer<float4>(*image);
    for (const auto& rows : seen)
        for (size_t i = 0; i < rows.size(); ++i) {
            const float4 a = rows[i], b = final_image[i];
            ASSERT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z && a.w == b.w) << i;
        }
}

}  // namespace
}  // namespace lucent_tests

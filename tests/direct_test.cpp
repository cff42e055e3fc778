// The direct-lighting sample on the built-in Cornell box: the light shows its emission, the
// walls their colours, and faces turned away from the light stay black.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "samples/sample.h"
#include "samples/stages.h"
#include "scene/image_io.h"
#include "tests/test_support.h"

namespace {

using lucent::samples::RenderResult;
using lucent::samples::RenderSettings;

RenderResult render(const std::string& scene, unsigned size = 96) {
    RenderSettings settings;
    settings.width = settings.height = size;
    settings.backend = lucent_tests::test_backend();  // LUCENT_TEST_BACKEND=cuda: the GPU
    settings.scene = scene;
    settings.sets["area_samples"] = "16";
    return lucent::samples::find_sample("direct").render(settings);
}

float3 pixel(const RenderResult& r, float fx, float fy) {
    return r.image.pixels[size_t(fy * r.image.height) * r.image.width + size_t(fx * r.image.width)];
}

TEST(DirectSample, CornellLightWallsAndFacesTurnedAway) {
    const RenderResult r = render("cornell");
    EXPECT_EQ(r.report.exception_count(), 0u);
    // The ceiling light, top centre: its emission exactly (it faces away from itself).
    const float3 light = pixel(r, 0.5f, 0.13f);
    EXPECT_FLOAT_EQ(light.x, 17.f);
    EXPECT_FLOAT_EQ(light.y, 12.f);
    EXPECT_FLOAT_EQ(light.z, 4.f);
    const float3 left = pixel(r, 0.06f, 0.5f), right = pixel(r, 0.94f, 0.5f);
    EXPECT_GT(left.x, 3 * left.y) << "the left wall is red";
    EXPECT_GT(right.y, 2 * right.x) << "the right wall is green";
    // The floor left of the blocks is lit; the short block's front face, turned away from
    // the ceiling light, receives exactly nothing.
    const float3 floor = pixel(r, 0.4f, 0.9f), turned_away = pixel(r, 0.6f, 0.9f);
    EXPECT_GT(floor.x + floor.y + floor.z, 0.2f);
    EXPECT_EQ(turned_away.x + turned_away.y + turned_away.z, 0.0f);
}

TEST(DirectSample, PointLightVariantLightsTheFloor) {
    const RenderResult r = render("cornell-point", 96);
    const float3 floor = pixel(r, 0.4f, 0.9f), ceiling = pixel(r, 0.5f, 0.03f);
    EXPECT_GT(floor.x + floor.y + floor.z, 0.05f);
    // The point hangs 10 cm below the ceiling light: the ceiling around it is lit too.
    EXPECT_GT(ceiling.x + ceiling.y + ceiling.z, 0.05f * (floor.x + floor.y + floor.z));
}

TEST(DirectSample, DiffuseMapFromAnMtlTexturesTheSurface) {
    // A quad facing the camera with a 2x2 texture: red on the left, blue on the right.
    namespace fs = std::filesystem;
    const fs::path dir =
        fs::temp_directory_path() / ("lucent-direct-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    lucent::scene::Image texture;
    texture.width = texture.height = 2;
    texture.pixels = {make_float3(1, 0, 0), make_float3(0, 0, 1), make_float3(1, 0, 0),
                      make_float3(0, 0, 1)};
    lucent::scene::write_image((dir / "rb.png").string(), texture);
    std::ofstream(dir / "quad.mtl") << "newmtl tex\nKd 1 1 1\nmap_Kd rb.png\n";
    std::ofstream(dir / "quad.obj") << "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
                                       "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl tex\n"
                                       "f 1/1 2/2 3/3 4/4\n";
    std::ofstream(dir / "scene.json")
        << R"({"camera": {"eye": [0, 0, 3], "look": [0, 0, 0], "fov": 50},
               "meshes": [{"file": "quad.obj"}],
               "lights": [{"type": "point", "position": [0, 0, 2], "intensity": [10, 10, 10]}]})";
    const RenderResult r = render((dir / "scene.json").string(), 64);
    fs::remove_all(dir);
    const float3 left = pixel(r, 0.3f, 0.5f), right = pixel(r, 0.7f, 0.5f);
    EXPECT_GT(left.x, 10 * left.z) << "left half red";
    EXPECT_GT(right.z, 10 * right.x) << "right half blue";
}

// `render --repeat N` times the launches after the launch-shape tuning: a trial launch runs
// a shape being tried, and one after timing began drops what came before it.
TEST(TimedLaunch, TrialLaunchesAreLeftOutOfTheMedian) {
    lucent::samples::SteadyLaunches steady;
    auto launch = [&](double ms, bool trial) {
        lucent::LaunchReport r;
        r.launch_ms = ms;
        r.kernel_ms = ms - 0.1;
        r.launch_shape_trial = trial;
        steady.add(r);
    };
    launch(3.0, true);
    launch(1.0, false);
    launch(1.1, false);
    launch(4.0, true);  // a variant arrived: its shapes are tried, the choice may change
    launch(0.6, false);
    launch(0.7, false);
    EXPECT_EQ(steady.trials, 2u);
    EXPECT_EQ(steady.ms, (std::vector<double>{0.6, 0.7}));
    ASSERT_EQ(steady.kernel_ms.size(), 2u);
    EXPECT_DOUBLE_EQ(steady.kernel_ms[1], 0.6);
}

TEST(TimedLaunch, RenderRepeatReportsTheMedianOfTheRepeats) {
    RenderSettings settings;
    settings.width = settings.height = 32;
    settings.backend = lucent_tests::test_backend();
    settings.scene = "cornell";
    settings.repeat = 4;
    const RenderResult r = lucent::samples::find_sample("direct").render(settings);
    const lucent::samples::StageTiming* launch = nullptr;
    for (const auto& stage : r.stages)
        if (stage.name == "launch") launch = &stage;
    ASSERT_NE(launch, nullptr);
    EXPECT_EQ(launch->note.rfind("median of 3 ", 0), 0u) << launch->note;
    EXPECT_GT(launch->ms, 0.0);
}

}  // namespace

// The `lucent` command line, run as a user would: bad input gives exit code 2 (1 for runtime
// errors), a message naming the flag and the accepted form, and never an output file.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "samples/sample.h"
#include "scene/exr_encoder.h"
#include "scene/image_io.h"

namespace {

namespace fs = std::filesystem;

struct CliRun {
    int exit_code = -1;
    std::string output;  // stdout and stderr together
};

CliRun run_cli(const std::string& args) {
    const std::string command = std::string("'") + LUCENT_CLI + "' " + args + " 2>&1";
    CliRun run;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return run;
    char buffer[4096];
    size_t n;
    while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) run.output.append(buffer, n);
    const int status = pclose(pipe);
    run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return run;
}

/// A fresh directory per test, so tests can run in parallel and check what was written.
class CliTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
        m_dir = fs::temp_directory_path() /
                ("lucent_cli_test_" + std::to_string(getpid()) + "_" + test->name());
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override { fs::remove_all(m_dir); }

    std::string path(const std::string& name) const { return (m_dir / name).string(); }
    bool dir_is_empty() const { return fs::is_empty(m_dir); }

    /// Runs `lucent render <args> --out <dir>/out.png` and checks the usage-error contract.
    CliRun expect_render_usage_error(const std::string& args) {
        CliRun run = run_cli("render " + args + " --out '" + path("out.png") + "'");
        EXPECT_EQ(run.exit_code, 2) << "lucent render " << args << "\n" << run.output;
        EXPECT_TRUE(dir_is_empty()) << "lucent render " << args << " left a file behind";
        return run;
    }

    fs::path m_dir;
};

const lucent::samples::Sample& whitted() {
    return lucent::samples::find_sample("whitted");
}

TEST_F(CliTest, ZeroSizeIsAUsageError) {
    CliRun run = expect_render_usage_error("--size 0x5");
    EXPECT_NE(run.output.find("--size"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("0x5"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("WxH"), std::string::npos) << run.output;
}

TEST_F(CliTest, NonNumericSizeIsAUsageError) {
    CliRun run = expect_render_usage_error("--size abc");
    EXPECT_NE(run.output.find("abc"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("WxH"), std::string::npos) << run.output;
}

TEST_F(CliTest, UnknownFlagIsAUsageError) {
    CliRun run = expect_render_usage_error("--no-such-flag");
    EXPECT_NE(run.output.find("--no-such-flag"), std::string::npos) << run.output;
}

TEST_F(CliTest, UnknownSampleListsTheSamples) {
    CliRun run = expect_render_usage_error("--sample no_such_sample");
    EXPECT_NE(run.output.find("no_such_sample"), std::string::npos) << run.output;
    for (const lucent::samples::Sample* info : lucent::samples::all_samples())
        EXPECT_NE(run.output.find(info->name), std::string::npos) << run.output;
}

TEST_F(CliTest, SetWithoutEqualsIsAUsageError) {
    CliRun run = expect_render_usage_error("--set no_equals_sign");
    EXPECT_NE(run.output.find("NAME=VALUE"), std::string::npos) << run.output;
}

TEST_F(CliTest, UnknownSetNameListsTheOptions) {
    CliRun run = expect_render_usage_error("--set no_such_option=1");
    EXPECT_NE(run.output.find("no_such_option"), std::string::npos) << run.output;
    for (const auto& option : whitted().options)
        EXPECT_NE(run.output.find(option.name), std::string::npos) << run.output;
}

TEST_F(CliTest, BadSetValueNamesTheOptionAndRange) {
    if (whitted().options.empty()) GTEST_SKIP() << "the whitted sample has no --set options";
    const std::string name = whitted().options.front().name;
    CliRun run = expect_render_usage_error("--set " + name + "=not_a_number");
    EXPECT_NE(run.output.find(name + "=not_a_number"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("expected"), std::string::npos) << run.output;
}

TEST_F(CliTest, UnknownExtensionNamesTheAcceptedOnes) {
    CliRun run = run_cli("render --size 8x8 --out '" + path("out.jpg") + "'");
    EXPECT_EQ(run.exit_code, 2) << run.output;
    EXPECT_NE(run.output.find(".png"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find(".pfm"), std::string::npos) << run.output;
    EXPECT_TRUE(dir_is_empty());
}

TEST_F(CliTest, UnknownBackendIsAUsageError) {
    CliRun run = expect_render_usage_error("--backend gpu");
    EXPECT_NE(run.output.find("auto, cpu or cuda"), std::string::npos) << run.output;
}

TEST_F(CliTest, BadDeviceListNamesTheFlagAndTheItem) {
    CliRun run = expect_render_usage_error("--devices 0,gpu1");
    EXPECT_NE(run.output.find("--devices"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("'gpu1'"), std::string::npos) << run.output;
}

TEST_F(CliTest, TwoCpuDevicesRenderTheImageOfOne) {
    ASSERT_EQ(run_cli("render --size 48x40 --threads 1 --backend cpu --out '" + path("one.pfm") + "'")
                  .exit_code,
              0);
    CliRun run = run_cli("render --size 48x40 --threads 1 --devices cpu,cpu --out '" +
                         path("two.pfm") + "'");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("2 devices"), std::string::npos) << run.output;
    std::ifstream a(path("one.pfm"), std::ios::binary), b(path("two.pfm"), std::ios::binary);
    const std::string one((std::istreambuf_iterator<char>(a)), {}),
        two((std::istreambuf_iterator<char>(b)), {});
    EXPECT_FALSE(one.empty());
    EXPECT_EQ(one, two) << "the same image, byte for byte";
}

TEST_F(CliTest, CudaBackendRendersOrSaysWhyNot) {
    CliRun run = run_cli("render --size 16x16 --backend cuda --out '" + path("out.png") + "'");
    if (run.exit_code == 0) {  // a build with CUDA on a machine with a GPU
        EXPECT_TRUE(fs::exists(path("out.png")));
        return;
    }
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_NE(run.output.find("error"), std::string::npos) << run.output;
    EXPECT_TRUE(dir_is_empty());
}

TEST_F(CliTest, NoSubcommandIsAUsageError) {
    CliRun run = run_cli("");
    EXPECT_EQ(run.exit_code, 2) << run.output;
}

TEST_F(CliTest, BenchMissingSceneIsARuntimeError) {
    CliRun run = run_cli("bench rays --scene '" + path("missing.obj") + "'");
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_NE(run.output.find("missing.obj"), std::string::npos) << run.output;
}

TEST_F(CliTest, BenchPartialCameraNamesTheMissingFlags) {
    CliRun run = run_cli("bench rays --scene '" + path("scene.obj") + "' --eye 1,2,3");
    EXPECT_EQ(run.exit_code, 2) << run.output;
    EXPECT_NE(run.output.find("--look"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("--light"), std::string::npos) << run.output;
}

TEST_F(CliTest, BenchBadVectorIsAUsageError) {
    CliRun run = run_cli("bench rays --scene '" + path("scene.obj") +
                         "' --eye 1,2 --look 0,0,0 --up 0,1,0 --fov 45 --light 0,5,0");
    EXPECT_EQ(run.exit_code, 2) << run.output;
    EXPECT_NE(run.output.find("--eye"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("x,y,z"), std::string::npos) << run.output;
}

TEST_F(CliTest, RenderHelpListsSamplesAndOptions) {
    CliRun run = run_cli("render --help");
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("Examples"), std::string::npos) << run.output;
    for (const lucent::samples::Sample* info : lucent::samples::all_samples()) {
        EXPECT_NE(run.output.find(info->name), std::string::npos) << run.output;
        for (const auto& option : info->options)
            EXPECT_NE(run.output.find(option.name + "=" + option.default_value), std::string::npos)
                << run.output;
    }
}

TEST_F(CliTest, RenderWritesAPngOfTheRequestedSize) {
    const std::string out = path("whitted.png");
    CliRun run = run_cli("render --sample whitted --size 64x48 --out '" + out + "'");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("total"), std::string::npos) << run.output;
    const lucent::scene::Image8 image = lucent::scene::read_png8(out);
    EXPECT_EQ(image.width, 64u);
    EXPECT_EQ(image.height, 48u);
    // The write is atomic: the temporary file is gone, only the image is left.
    EXPECT_EQ(std::distance(fs::directory_iterator(m_dir), fs::directory_iterator()), 1);
}

TEST_F(CliTest, RenderWritesAPfmByExtension) {
    const std::string out = path("whitted.pfm");
    CliRun run = run_cli("render --size 16x8 --out '" + out + "'");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    std::ifstream file(out, std::ios::binary);
    std::string header(12, '\0');
    file.read(header.data(), std::streamsize(header.size()));
    EXPECT_EQ(header, "PF\n16 8\n-1.0");
    EXPECT_EQ(fs::file_size(out), 12 + 1 + 16u * 8u * 3u * sizeof(float));
}

/// A file's bytes: two .pfm images of the same size are the same image when these are.
std::string file_bytes(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string flag_vector(float3 v) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "%.9g,%.9g,%.9g", double(v.x), double(v.y), double(v.z));
    return buf;
}

TEST_F(CliTest, CameraFlagsReplaceThePartsOfTheScenesCameraTheyGive) {
    const std::string base = "render --sample direct --size 32x24 --threads 1 --out ";
    ASSERT_EQ(run_cli(base + "'" + path("own.pfm") + "'").exit_code, 0);
    // The scene's own eye, given as a flag: the same camera, the same image.
    const lucent::scene::Camera own = lucent::scene::load_scene("cornell").camera;
    CliRun same = run_cli(base + "'" + path("same.pfm") + "' --eye " + flag_vector(own.eye));
    ASSERT_EQ(same.exit_code, 0) << same.output;
    EXPECT_EQ(file_bytes(path("own.pfm")), file_bytes(path("same.pfm")));
    // Another field of view alone: the same eye and look, a narrower view.
    CliRun narrow = run_cli(base + "'" + path("narrow.pfm") + "' --fov 10");
    ASSERT_EQ(narrow.exit_code, 0) << narrow.output;
    EXPECT_NE(file_bytes(path("own.pfm")), file_bytes(path("narrow.pfm")));
    // The whitted and fog samples, which have cameras of their own, take the flags too.
    for (const char* sample : {"whitted", "fog"}) {
        CliRun run = run_cli(std::string("render --sample ") + sample +
                             " --size 16x16 --fov 20 --out '" + path(sample + std::string(".pfm")) + "'");
        EXPECT_EQ(run.exit_code, 0) << sample << ": " << run.output;
    }
}

TEST_F(CliTest, ACameraThatCannotSeeIsRefusedByName) {
    CliRun same_point = expect_render_usage_error("--sample direct --size 8x8 --eye 1,2,3 --look 1,2,3");
    EXPECT_NE(same_point.output.find("eye and look are the same point (1,2,3)"), std::string::npos)
        << same_point.output;
    CliRun along = expect_render_usage_error("--sample igi --size 8x8 --eye 0,0,0 --look 0,5,0 --up 0,1,0");
    EXPECT_NE(along.output.find("along the view direction"), std::string::npos) << along.output;
    CliRun fov = expect_render_usage_error("--size 8x8 --fov 180");
    EXPECT_NE(fov.output.find("--fov '180': expected a number in (0, 180)"), std::string::npos)
        << fov.output;
    expect_render_usage_error("--size 8x8 --eye 1,2");
}

TEST_F(CliTest, RenderJsonIsOneObjectWithTheStages) {
    CliRun run = run_cli("render --sample whitted --size 16x16 --json --set lights=2 --fov 30 --out '" +
                         path("w.exr") + "'");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const nlohmann::json j = nlohmann::json::parse(run.output);  // nothing else is printed
    EXPECT_EQ(j["sample"], "whitted");
    EXPECT_EQ(j["width"], 16);
    EXPECT_EQ(j["sets"]["lights"], "2");
    EXPECT_EQ(j["camera"]["fov"], 30.0);
    EXPECT_FALSE(j["camera"].contains("eye"));
    ASSERT_FALSE(j["stages"].empty());
    bool launch = false;
    for (const auto& stage : j["stages"]) launch = launch || stage["name"] == "launch";
    EXPECT_TRUE(launch) << j.dump(2);
    EXPECT_GT(j["total_ms"].get<double>(), 0.0);
    EXPECT_EQ(j["out"], path("w.exr"));
    EXPECT_TRUE(fs::exists(path("w.exr")));
}

TEST_F(CliTest, JitCheckPrintsNoTimingItDidNotMeasure) {
    // Issue 21 item 7: with --jit-check the launch once printed -8203 ms (the compile
    // subtracted from a launch it preceded) and fog -0.14 frames/s. Every stage and rate
    // printed must be a measured, non-negative time; the JIT stage is one of them.
    CliRun run = run_cli("render --sample whitted --size 16x16 --jit-check sm_90 --json --out '" +
                         path("w.png") + "'");
    if (run.exit_code != 0 && (run.output.find("NVRTC") != std::string::npos ||
                               run.output.find("CUDA") != std::string::npos))
        GTEST_SKIP() << "no CUDA backend or NVRTC here: " << run.output;
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const nlohmann::json j = nlohmann::json::parse(run.output);
    bool jit = false, launch = false;
    for (const auto& stage : j["stages"]) {
        EXPECT_GE(stage["ms"].get<double>(), 0.0) << stage.dump();
        jit = jit || stage["name"].get<std::string>().find("JIT") != std::string::npos;
        launch = launch || stage["name"] == "launch";
    }
    EXPECT_TRUE(jit) << j.dump(2);
    EXPECT_TRUE(launch) << j.dump(2);
    // The text form, for the fog sample's frames/s too: no negative number anywhere.
    run = run_cli("render --sample fog --size 16x16 --jit-check sm_90 --out '" + path("f.png") +
                  "'");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("frames/s"), std::string::npos) << run.output;
    for (size_t at = run.output.find('-'); at != std::string::npos;
         at = run.output.find('-', at + 1)) {
        const bool number = at + 1 < run.output.size() &&
                            std::isdigit(static_cast<unsigned char>(run.output[at + 1])) &&
                            (at == 0 || run.output[at - 1] == ' ');
        EXPECT_FALSE(number) << "a negative figure in: " << run.output;
    }
}

TEST_F(CliTest, BadAovNamesTheFlagTheValueAndTheAcceptedOnes) {
    CliRun run = expect_render_usage_error("--sample pathtracer --size 8x8 --aov albedo,nrmal");
    EXPECT_NE(run.output.find("--aov 'albedo,nrmal': unknown AOV 'nrmal' (did you mean 'normal'?)"),
              std::string::npos)
        << run.output;
    EXPECT_NE(run.output.find("accepted: albedo, normal, depth, position, instance"),
              std::string::npos)
        << run.output;
    run = expect_render_usage_error("--sample pathtracer --size 8x8 --aov ''");
    EXPECT_NE(run.output.find("--aov ''"), std::string::npos) << run.output;
}

TEST_F(CliTest, AovWithoutAnExrOutputSaysToUseExr) {
    CliRun run = expect_render_usage_error("--sample pathtracer --size 8x8 --aov depth");
    EXPECT_NE(run.output.find("use --out NAME.exr"), std::string::npos) << run.output;
}

TEST_F(CliTest, AovOrDenoiseOnASampleWithoutAGBufferNamesTheOnesWithIt) {
    for (const char* flag : {"--denoise", "--aov depth"}) {
        CliRun run = run_cli(std::string("render --sample whitted --size 8x8 ") + flag +
                             " --out '" + path("w.exr") + "'");
        EXPECT_EQ(run.exit_code, 2) << run.output;
        EXPECT_NE(run.output.find("has no G-buffer pass; the samples with one are"),
                  std::string::npos)
            << run.output;
        EXPECT_TRUE(dir_is_empty());
    }
}

TEST_F(CliTest, RenderAovWritesLayersAlphaAndMetadataIntoTheExr) {
    if (!lucent::scene::exr_supported()) GTEST_SKIP() << "built without OpenEXR";
    const std::string out = path("pt.exr");
    CliRun run = run_cli("render --sample pathtracer --size 16x12 --spp 2 --threads 2 -q "
                         "--aov albedo,normal,depth,position,instance --denoise --set seed=3 "
                         "--out '" + out + "'");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const lucent::scene::ExrFile exr = lucent::scene::read_exr_file(out);
    EXPECT_EQ(exr.image.width, 16u);
    for (const char* c : {"A", "Albedo.R", "Albedo.G", "Albedo.B", "Nx", "Ny", "Nz", "Px", "Py",
                          "Pz", "Z", "InstanceId"})
        EXPECT_TRUE(exr.channels.count(c)) << c;
    EXPECT_EQ(exr.attributes.at("lucent.sample"), "pathtracer");
    EXPECT_EQ(exr.attributes.at("lucent.spp"), "2");
    EXPECT_EQ(exr.attributes.at("lucent.denoise"), "1");
    const nlohmann::json sets = nlohmann::json::parse(exr.attributes.at("lucent.sets"));
    EXPECT_EQ(sets["seed"], "3");
    const nlohmann::json camera = nlohmann::json::parse(exr.attributes.at("lucent.camera"));
    EXPECT_EQ(camera["eye"].size(), 3u);
    const nlohmann::json render = nlohmann::json::parse(exr.attributes.at("lucent.render"));
    EXPECT_EQ(render["aovs"].size(), 12u) << render.dump(2);  // A and the 11 layers
    bool denoise = false;
    for (const auto& stage : render["stages"]) denoise = denoise || stage["name"] == "denoise";
    EXPECT_TRUE(denoise) << render.dump(2);
    // A plain .exr of the same sample has RGBA and the metadata, no other layer.
    ASSERT_EQ(run_cli("render --sample pathtracer --size 8x8 --spp 1 -q --out '" + path("a.exr") +
                      "'").exit_code,
              0);
    const lucent::scene::ExrFile plain = lucent::scene::read_exr_file(path("a.exr"));
    EXPECT_EQ(plain.channels.size(), 1u);
    EXPECT_TRUE(plain.channels.count("A"));
    EXPECT_TRUE(plain.attributes.count("lucent.render"));
}

TEST_F(CliTest, CompareGivesTheFiguresAndFailsAboveAThreshold) {
    for (const char* set : {"ambient=0.05", "ambient=0.3"})
        ASSERT_EQ(run_cli(std::string("render --sample direct --size 32x32 -q --set ") + set +
                          " --out '" + path(set) + ".pfm'")
                      .exit_code,
                  0);
    const std::string a = path("ambient=0.05") + ".pfm", b = path("ambient=0.3") + ".pfm";
    CliRun same = run_cli("compare '" + a + "' '" + a + "' --json");
    ASSERT_EQ(same.exit_code, 0) << same.output;
    const nlohmann::json s = nlohmann::json::parse(same.output);
    EXPECT_EQ(s["rmse"], 0.0);
    EXPECT_EQ(s["flip_max"], 0.0);
    EXPECT_TRUE(s["psnr_db"].is_null());  // infinite
    CliRun differ = run_cli("compare '" + a + "' '" + b + "' --error-image '" + path("flip.exr") +
                            "' --fail-above 0.01");
    EXPECT_EQ(differ.exit_code, 1) << differ.output;
    EXPECT_NE(differ.output.find("is above --fail-above 0.01"), std::string::npos) << differ.output;
    EXPECT_TRUE(fs::exists(path("flip.exr")));
    EXPECT_EQ(run_cli("compare '" + a + "' '" + b + "' --fail-above 0.99").exit_code, 0);
    // Images of two sizes: an error naming both, and no error image.
    ASSERT_EQ(run_cli("render --size 8x8 -q --out '" + path("small.png") + "'").exit_code, 0);
    CliRun sizes = run_cli("compare '" + a + "' '" + path("small.png") + "' --error-image '" +
                           path("none.png") + "'");
    EXPECT_EQ(sizes.exit_code, 1);
    EXPECT_NE(sizes.output.find("the images differ in size (32x32 and 8x8)"), std::string::npos)
        << sizes.output;
    EXPECT_FALSE(fs::exists(path("none.png")));
    EXPECT_EQ(run_cli("compare '" + a + "' --ppd 0").exit_code, 2);
}

TEST_F(CliTest, QuietRenderPrintsNothing) {
    CliRun run = run_cli("render --size 16x16 --backend cpu -q --out '" + path("q.png") + "'");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_EQ(run.output, "");
    EXPECT_TRUE(fs::exists(path("q.png")));
}

}  // namespace

namespace {

TEST(CliBenchIgi, RunsEveryConfigurationForEveryVplCount) {
    CliRun run = run_cli("bench igi --size 32x24 --frames 1 --vpls 4,8 --json");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const nlohmann::json result = nlohmann::json::parse(run.output);
    const nlohmann::json& rows = result.at("rows");
    ASSERT_EQ(rows.size(), 12u) << run.output;
    size_t row = 0;
    for (const char* c : {"canonical", "imperfect, box graph", "imperfect, maps",
                          "+imperfect visibility", "+downsampling", "+interleaving"})
        for (unsigned v : {4u, 8u}) {
            EXPECT_EQ(rows[row].at("configuration"), c) << run.output;
            EXPECT_EQ(rows[row].at("vpls"), v) << run.output;
            ++row;
        }
    // Interleaving adds the discontinuity filter; the canonical frame has none.
    EXPECT_FALSE(rows[0].at("stage_ms").contains("discontinuity filter")) << run.output;
    EXPECT_TRUE(rows[10].at("stage_ms").contains("discontinuity filter")) << run.output;
}

TEST(CliBenchIgi, BadVplCountNamesTheFlagAndRange) {
    CliRun run = run_cli("bench igi --vpls 30,0");
    EXPECT_EQ(run.exit_code, 2) << run.output;
    EXPECT_NE(run.output.find("--vpls"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("65536"), std::string::npos) << run.output;
}

}  // namespace

TEST_F(CliTest, BenchBuildSubdivideCutsEveryTriangleIntoFourPerLevel) {
    {
        std::ofstream obj(path("quad.obj"));
        obj << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";
    }
    CliRun run = run_cli("bench build --scene '" + path("quad.obj") +
                         "' --subdivide 2 --repeat 1 --no-peer --json");
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("\"triangles\": 32"), std::string::npos) << run.output;
}

TEST_F(CliTest, BenchBuildBadSubdivideOrSizeNamesTheFlag) {
    CliRun run = run_cli("bench build --scene '" + path("scene.obj") + "' --subdivide 9");
    EXPECT_EQ(run.exit_code, 2) << run.output;
    EXPECT_NE(run.output.find("--subdivide"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("--subdivide '9': expected a number in [0, 5]"), std::string::npos)
        << run.output;
    run = run_cli("bench build --scene '" + path("scene.obj") + "' --size 0x5");
    EXPECT_EQ(run.exit_code, 2) << run.output;
    EXPECT_NE(run.output.find("--size"), std::string::npos) << run.output;
    EXPECT_TRUE(dir_is_empty());
}

TEST_F(CliTest, BenchRaysNamesTheTraversalVariantThatRan) {
    {
        std::ofstream obj(path("quad.obj"));
        obj << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";
    }
    const std::string args = "bench rays --scene '" + path("quad.obj") +
                             "' --eye 0.5,0.5,2 --look 0.5,0.5,0 --up 0,1,0 --fov 45 "
                             "--light 0.5,0.5,3 --size 16x16 --repeat 1 --no-peer";
    CliRun run = run_cli(args);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("cpu isa "), std::string::npos) << run.output;
    // LUCENT_CPU_ISA picks the variant; every build has the scalar one. Set for the one
    // command (ctest runs each test in a process of its own).
    setenv("LUCENT_CPU_ISA", "scalar", 1);
    run = run_cli(args + " --json");
    unsetenv("LUCENT_CPU_ISA");
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("\"cpu_isa\": \"scalar\""), std::string::npos) << run.output;
}

// A scene path is text like any other in the JSON: quotes and backslashes in it are escaped,
// and the output parses back to the path.
TEST_F(CliTest, BenchJsonOfAScenePathWithQuotesParsesBack) {
    const std::string scene = path("my \"quoted\" scene\\1.obj");
    {
        std::ofstream obj(scene);
        obj << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";
    }
    CliRun run = run_cli("bench rays --scene '" + scene +
                         "' --eye 0.5,0.5,2 --look 0.5,0.5,0 --up 0,1,0 --fov 45 "
                         "--light 0.5,0.5,3 --size 8x8 --repeat 1 --no-peer --json");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    nlohmann::json result;
    ASSERT_NO_THROW(result = nlohmann::json::parse(run.output)) << run.output;
    EXPECT_EQ(result.at("scene").get<std::string>(), scene);
    EXPECT_EQ(result.at("triangles"), 2) << run.output;
    EXPECT_GT(result.at("lucent").at("primary").at("hits").get<int>(), 0) << run.output;

    run = run_cli("bench build --scene '" + scene + "' --repeat 1 --no-peer --json");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    ASSERT_NO_THROW(result = nlohmann::json::parse(run.output)) << run.output;
    EXPECT_EQ(result.at("scene").get<std::string>(), scene);
}

namespace {

/// Every key path of a JSON document ("/rows[]/stage_ms"), arrays by their first element.
void collect_key_paths(const nlohmann::json& node, const std::string& path,
                       std::set<std::string>& out) {
    if (node.is_object()) {
        for (const auto& [key, value] : node.items()) {
            out.insert(path + "/" + key);
            collect_key_paths(value, path + "/" + key, out);
        }
    } else if (node.is_array() && !node.empty()) {
        collect_key_paths(node.front(), path + "[]", out);
    }
}

std::set<std::string> key_paths(const nlohmann::json& document) {
    std::set<std::string> paths;
    collect_key_paths(document, "", paths);
    return paths;
}

std::string missing_from(const std::set<std::string>& a, const std::set<std::string>& b) {
    std::string missing;
    for (const std::string& key : a)
        if (!b.count(key)) missing += " " + key;
    return missing;
}

nlohmann::json recorded_result(const std::string& name) {
    std::ifstream file(std::string(LUCENT_TESTS_DIR) + "/../docs/bench/" + name);
    return nlohmann::json::parse(file);
}

// The JSON results keep the field names of the results recorded in docs/bench, which
// scripts read: the same keys, at the same places.
TEST(CliBenchJson, FogAndIgiKeepTheRecordedFieldNames) {
    CliRun run = run_cli("bench fog --size 16x12 --frames 1 --json");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    std::set<std::string> now = key_paths(nlohmann::json::parse(run.output));
    std::set<std::string> recorded = key_paths(recorded_result("fog-cuda.json"));
    EXPECT_EQ(missing_from(now, recorded), "") << run.output;
    EXPECT_EQ(missing_from(recorded, now), "") << run.output;

    run = run_cli("bench igi --size 16x12 --frames 1 --vpls 4 --json");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    now = key_paths(nlohmann::json::parse(run.output));
    recorded = key_paths(recorded_result("igi-cuda-sponza.json"));
    EXPECT_EQ(missing_from(now, recorded), "") << run.output;
    EXPECT_EQ(missing_from(recorded, now), "") << run.output;
}

TEST(CliBenchJson, RaysKeepsTheRecordedFieldNames) {
    const std::string scene = std::string(LUCENT_SCENES_DIR) + "/bunny.obj";
    if (!fs::exists(scene)) GTEST_SKIP() << scene << " is not here";
    CliRun run = run_cli("bench rays --scene '" + scene + "' --size 32x24 --repeat 1 --json");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const nlohmann::json result = nlohmann::json::parse(run.output);
    std::set<std::string> now = key_paths(result);
    std::set<std::string> recorded = key_paths(recorded_result("rays-cpu-bunny.json"));
    recorded.insert("/cpu_isa");  // added after that record was made
    // The stream queries' figures were added after that record too. They take the kernels'
    // ("lucent") fields, plus their own ratio to the peer and their checksums' verdict.
    ASSERT_TRUE(result.contains("streams")) << run.output;
    for (const std::string& key : key_paths(result["lucent"])) recorded.insert("/streams" + key);
    recorded.insert("/streams");
    recorded.insert("/streams/checksums_agree_with_kernels");
    if (result.contains("embree")) {
        for (const char* set : {"", "/primary", "/shadow", "/diffuse"})
            recorded.insert(std::string("/streams/ratio_to_embree") + set);
    }
    EXPECT_EQ(missing_from(now, recorded), "") << run.output;
    if (result.contains("embree"))  // a build with the peer gives every recorded field
        EXPECT_EQ(missing_from(recorded, now), "") << run.output;
}

// `lucent bench present` opens OpenGL through EGL without a window (Mesa's software device
// here), shows frames the way `lucent view` does and reads the framebuffer back.
TEST(CliBenchPresent, ShowsExactlyWhatWasRenderedInAHeadlessContext) {
    CliRun run = run_cli("bench present --backend cpu --threads 2 --size 48x32 --frames 2 --json");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("\"path\": \"host upload\""), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("\"shown_equals_rendered\": true"), std::string::npos)
        << run.output;
    EXPECT_EQ(run.output.find("\"shown_equals_rendered\": false"), std::string::npos)
        << run.output;
}

TEST(CliBenchPresent, BadFlagsNameTheFlag) {
    CliRun run = run_cli("bench present --size 0x5");
    EXPECT_EQ(run.exit_code, 2) << run.output;
    EXPECT_NE(run.output.find("--size"), std::string::npos) << run.output;
    run = run_cli("bench present --sample nosuch");
    EXPECT_NE(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("nosuch"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("whitted"), std::string::npos) << run.output;
}

}  // namespace

namespace {

TEST_F(CliTest, CameraOutOfRangeNamesTheCountAndWritesNothing) {
    CliRun run = expect_render_usage_error("--sample direct --scene cornell --size 8x8 --camera 2");
    EXPECT_NE(run.output.find("--camera 2: scene 'cornell' has 0 cameras of its own"),
              std::string::npos)
        << run.output;
    run = expect_render_usage_error("--size 8x8 --camera 0");  // whitted: its own scene
    EXPECT_NE(run.output.find("scene 'whitted' has 0 cameras of its own"), std::string::npos)
        << run.output;
}

TEST_F(CliTest, MalformedGltfIsOneLineNamingTheJsonPathAndWritesNothing) {
    const fs::path scene = fs::temp_directory_path() /
                           ("lucent_cli_test_" + std::to_string(getpid()) + "_bad.gltf");
    std::ofstream(scene) << R"({"asset": {"version": "2.0"}, "nodes": [{"mesh": 3}], "meshes": []})";
    CliRun run = run_cli("render --sample direct --size 8x8 --scene '" + scene.string() +
                         "' --out '" + path("out.png") + "'");
    fs::remove(scene);
    EXPECT_NE(run.exit_code, 0) << run.output;
    EXPECT_TRUE(dir_is_empty()) << "a failed render left a file behind";
    EXPECT_NE(run.output.find(scene.string() + ": nodes[0].mesh: mesh 3 is out of range (the "
                                               "file has 0)"),
              std::string::npos)
        << run.output;
}

}  // namespace

// `bench spheres` times the built-in spheres against the same spheres as a custom program:
// both paths must give every pixel the same sphere, and rays must hit (a field, not a void).
TEST(CliBenchJson, SpheresBenchComparesTheSameWork) {
    CliRun run = run_cli("bench spheres --count 5000 --size 64x48 --repeat 2 --json");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const nlohmann::json result = nlohmann::json::parse(run.output);
    EXPECT_EQ(result["spheres"], 5000);
    EXPECT_EQ(result["pixels_that_differ"], 0);
    EXPECT_GT(result["hit_fraction"].get<double>(), 0.5);
    EXPECT_GT(result["builtin_mrays"]["mrays"].get<double>(), 0.0);
    EXPECT_GT(result["custom_mrays"]["mrays"].get<double>(), 0.0);
    // The CPU has no launch-shape tuning: no trial launch to leave out.
    EXPECT_EQ(result["launch_shape_trials_left_out"], 0);
}

// `bench curves` times primary rays into a head of hair and one diffuse ray per primary hit.
TEST(CliBenchJson, CurvesBenchTimesBothRaySets) {
    CliRun run = run_cli("bench curves --segments 2000 --size 64x48 --repeat 2 --json");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const nlohmann::json result = nlohmann::json::parse(run.output);
    EXPECT_EQ(result["segments"], 2000);
    EXPECT_GT(result["primary_hit_fraction"].get<double>(), 0.1);
    EXPECT_GT(result["diffuse_hit_fraction"].get<double>(), 0.0);
    EXPECT_GT(result["primary_mrays"]["mrays"].get<double>(), 0.0);
    EXPECT_GT(result["diffuse_mrays"]["mrays"].get<double>(), 0.0);
    EXPECT_EQ(result["launch_shape_trials_left_out"], 0);
}

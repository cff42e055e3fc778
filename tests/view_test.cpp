// `lucent view`, run as a user would: its input checks, and the headless check under Xvfb
// (Mesa's software OpenGL): the window's pixels after N frames equal `lucent render`'s image
// of the same view. Skipped when xvfb-run is missing or this build has no viewer.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "scene/image_io.h"

namespace {

namespace fs = std::filesystem;

struct CliRun {
    int exit_code = -1;
    std::string output;  // stdout and stderr together
};

CliRun run(const std::string& command) {
    CliRun r;
    FILE* pipe = popen((command + " 2>&1").c_str(), "r");
    if (!pipe) return r;
    char buffer[4096];
    size_t n;
    while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) r.output.append(buffer, n);
    const int status = pclose(pipe);
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

CliRun lucent(const std::string& args) {
    return run(std::string("'") + LUCENT_CLI + "' " + args);
}

class ViewTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
        m_dir = fs::temp_directory_path() /
                ("lucent_view_test_" + std::to_string(getpid()) + "_" + test->name());
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override { fs::remove_all(m_dir); }
    std::string path(const std::string& name) const { return (m_dir / name).string(); }
    fs::path m_dir;
};

bool has_viewer() {
    // A build without GLFW, ImGui or OpenGL says so in its help.
    return lucent("view --help").output.find("not in this build") == std::string::npos;
}

TEST_F(ViewTest, ScreenshotWithoutFramesIsAUsageError) {
    const CliRun r = lucent("view --screenshot '" + path("v.png") + "'");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--frames"), std::string::npos) << r.output;
}

TEST_F(ViewTest, ScreenshotMustBeAPng) {
    const CliRun r = lucent("view --frames 1 --screenshot '" + path("v.pfm") + "'");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(".png"), std::string::npos) << r.output;
}

TEST_F(ViewTest, BadInputNamesTheFlagOrOption) {
    CliRun r = lucent("view --size 0x10");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--size"), std::string::npos) << r.output;
    r = lucent("view --frames 0");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--frames"), std::string::npos) << r.output;
    r = lucent("view --sample whitted --set nope=1");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("nope"), std::string::npos) << r.output;
    r = lucent("view --sample nope");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("pathtracer"), std::string::npos) << r.output;  // lists them
    r = lucent("view --wobble");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--wobble"), std::string::npos) << r.output;
}

TEST_F(ViewTest, HelpListsTheKeysAndExamples) {
    const CliRun r = lucent("view --help");
    EXPECT_EQ(r.exit_code, 0);
    for (const char* text : {"Examples:", "orbit", "--screenshot", "--no-panel", "reset"})
        EXPECT_NE(r.output.find(text), std::string::npos) << text << "\n" << r.output;
}

TEST_F(ViewTest, WindowShowsWhatRenderWrites) {
    if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
        GTEST_SKIP() << "xvfb-run is not installed (apt-get install xvfb xauth)";
    if (!has_viewer()) GTEST_SKIP() << "this build has no viewer (GLFW, ImGui or OpenGL missing)";
    const std::string shot = path("view.png"), rendered = path("render.png");
    const CliRun view = run("xvfb-run -a -s '-screen 0 1280x1024x24' '" + std::string(LUCENT_CLI) +
                            "' view --sample whitted --size 160x120 --backend cpu --frames 3 "
                            "--no-panel --screenshot '" +
                            shot + "'");
    ASSERT_EQ(view.exit_code, 0) << view.output;
    const CliRun render =
        lucent("render --sample whitted --size 160x120 --backend cpu --out '" + rendered + "'");
    ASSERT_EQ(render.exit_code, 0) << render.output;
    const lucent::scene::Image8 a = lucent::scene::read_png8(shot);
    const lucent::scene::Image8 b = lucent::scene::read_png8(rendered);
    ASSERT_EQ(a.width, 160u);
    ASSERT_EQ(a.height, 120u);
    // The viewer's camera frame is computed in another float order than render's: allow a
    // few edge pixels (0.5 %), none of them far off.
    EXPECT_LE(lucent::scene::count_differing_pixels(a, b, 10), 96u);
    EXPECT_EQ(lucent::scene::count_differing_pixels(a, b, 128), 0u);
}

TEST_F(ViewTest, TwoDevicesShowWhatOneShows) {
    if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
        GTEST_SKIP() << "xvfb-run is not installed (apt-get install xvfb xauth)";
    if (!has_viewer()) GTEST_SKIP() << "this build has no viewer (GLFW, ImGui or OpenGL missing)";
    const std::string one = path("one.png"), two = path("two.png");
    const std::string view = "xvfb-run -a -s '-screen 0 1280x1024x24' '" +
                             std::string(LUCENT_CLI) +
                             "' view --sample whitted --size 160x120 --threads 1 --frames 3 "
                             "--no-panel ";
    ASSERT_EQ(run(view + "--backend cpu --screenshot '" + one + "'").exit_code, 0);
    const CliRun spread = run(view + "--devices cpu,cpu --screenshot '" + two + "'");
    ASSERT_EQ(spread.exit_code, 0) << spread.output;
    const lucent::scene::Image8 a = lucent::scene::read_png8(one);
    const lucent::scene::Image8 b = lucent::scene::read_png8(two);
    EXPECT_EQ(lucent::scene::count_differing_pixels(a, b, 0), 0u);
}

TEST_F(ViewTest, PanelIsDrawnOverTheImage) {
    if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
        GTEST_SKIP() << "xvfb-run is not installed (apt-get install xvfb xauth)";
    if (!has_viewer()) GTEST_SKIP() << "this build has no viewer (GLFW, ImGui or OpenGL missing)";
    const std::string with = path("with.png"), without = path("without.png");
    const std::string common = "' view --sample whitted --size 800x600 --backend cpu --frames 1 ";
    const std::string xvfb = "xvfb-run -a -s '-screen 0 1280x1024x24' '" + std::string(LUCENT_CLI);
    ASSERT_EQ(run(xvfb + common + "--screenshot '" + with + "'").exit_code, 0);
    ASSERT_EQ(run(xvfb + common + "--no-panel --screenshot '" + without + "'").exit_code, 0);
    const auto a = lucent::scene::read_png8(with), b = lucent::scene::read_png8(without);
    // The panel covers the top-left corner, not the whole window.
    const size_t differ = lucent::scene::count_differing_pixels(a, b, 10);
    EXPECT_GT(differ, 1000u);
    EXPECT_LT(differ, 800u * 600u / 2);
}

}  // namespace

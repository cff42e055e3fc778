// Images in and out: comparison (scene/image_compare.h, scene/flip.h) on images whose
// answers are known in closed form, FLIP's colour pipeline against published CIE L*a*b*
// values, its spatial behaviour; reading (scene/image_read.h) with bad input refused by
// name; and temporaries removed when a signal ends the writer (scene/temp_file_cleanup.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "lucent/error.h"
#include "scene/flip.h"
#include "scene/image_compare.h"
#include "scene/image_read.h"
#include "scene/temp_file_cleanup.h"

#include <csignal>
#include <sys/wait.h>
#include <unistd.h>

namespace {

using lucent::scene::compare_images;
using lucent::scene::Image;

Image flat(unsigned w, unsigned h, float3 c) {
    Image image;
    image.width = w;
    image.height = h;
    image.pixels.assign(size_t(w) * h, c);
    return image;
}

/// FLIP of two flat colours, from the paper's formulas and the L*a*b* values given, without
/// the code under test: flat images have no features and filtering leaves them as they are.
double flat_flip(double L1, double a1, double b1, double L2, double a2, double b2) {
    // Published CIE L*a*b* (D65) of sRGB green and blue, for c_max.
    const double Lg = 87.7347, ag = -86.1827, bg = 83.1793;
    const double Lb = 32.2970, ab = 79.1875, bb = -107.8602;
    auto hyab_hunt = [](double La, double aa, double ba, double Lz, double az, double bz) {
        const double da = 0.01 * La * aa - 0.01 * Lz * az, db = 0.01 * La * ba - 0.01 * Lz * bz;
        return std::fabs(La - Lz) + std::sqrt(da * da + db * db);
    };
    const double cmax = std::pow(hyab_hunt(Lg, ag, bg, Lb, ab, bb), 0.7);
    const double e = std::pow(hyab_hunt(L1, a1, b1, L2, a2, b2), 0.7);
    const double pccmax = 0.4 * cmax;
    return e < pccmax ? 0.95 / pccmax * e : 0.95 + (e - pccmax) / (cmax - pccmax) * 0.05;
}

/// CIE L* of a grey of linear value y (its a* and b* are 0).
double lightness(double y) {
    return y > 216.0 / 24389.0 ? 116.0 * std::cbrt(y) - 16.0 : y * 24389.0 / 27.0;
}

TEST(ImageCompare, IdenticalImagesAreZeroEverywhere) {
    Image a = flat(20, 10, make_float3(0.2f, 0.5f, 0.9f));
    a.pixels[37] = make_float3(4.0f, 0.0f, 1.0f);  // HDR values are fine
    const auto c = compare_images(a, a);
    EXPECT_EQ(c.rmse, 0.0);
    EXPECT_EQ(c.relmse, 0.0);
    EXPECT_TRUE(std::isinf(c.psnr_db));
    EXPECT_EQ(c.flip_max, 0.0);
    EXPECT_EQ(c.flip.size(), 200u);
}

TEST(ImageCompare, AConstantDifferenceHasItsClosedFormFigures) {
    const auto c = compare_images(flat(8, 8, make_float3(0.5f)), flat(8, 8, make_float3(0.6f)));
    EXPECT_NEAR(c.rmse, 0.1, 1e-6);
    EXPECT_NEAR(c.relmse, 0.01 / (0.25 + 0.01), 1e-6);
    EXPECT_NEAR(c.psnr_db, 20.0, 1e-4);
}

TEST(ImageCompare, FlipOfFlatColoursMatchesThePapersFormulasOnPublishedLab) {
    // Black against white: the largest lightness difference, above p_c c_max.
    auto c = compare_images(flat(16, 16, make_float3(0.0f)), flat(16, 16, make_float3(1.0f)));
    EXPECT_NEAR(c.flip_mean, flat_flip(0, 0, 0, 100, 0, 0), 2e-4);
    EXPECT_NEAR(c.flip_max - c.flip_median, 0.0, 1e-6);  // the same everywhere
    // Two greys: below p_c c_max, on the linear part of the redistribution.
    c = compare_images(flat(16, 16, make_float3(0.5f)), flat(16, 16, make_float3(0.6f)));
    EXPECT_NEAR(c.flip_mean, flat_flip(lightness(0.5), 0, 0, lightness(0.6), 0, 0), 2e-4);
    // Saturated green against blue is c_max itself: FLIP 1.
    c = compare_images(flat(16, 16, make_float3(0, 1, 0)), flat(16, 16, make_float3(0, 0, 1)));
    EXPECT_NEAR(c.flip_mean, 1.0, 1e-4);
    // Values above 1 are compared as displayed: clamped.
    c = compare_images(flat(4, 4, make_float3(1.0f)), flat(4, 4, make_float3(7.0f)));
    EXPECT_EQ(c.flip_max, 0.0);
    EXPECT_GT(c.rmse, 5.9);
}

TEST(ImageCompare, AFinePatternMattersLessToAFartherObserver) {
    // A one-pixel checkerboard of black and white against the grey of its mean: seen close
    // (few pixels per degree) the pattern is plain; from afar the eye averages it away.
    // 192 pixels a side: wider than the filters at every distance used, so the borders
    // (replicated) do not decide the figure.
    constexpr unsigned n = 192;
    Image checker = flat(n, n, make_float3(0.0f));
    for (unsigned y = 0; y < n; ++y)
        for (unsigned x = 0; x < n; ++x)
            if ((x + y) % 2) checker.pixels[y * n + x] = make_float3(1.0f);
    const Image grey = flat(n, n, make_float3(0.5f));
    const double close = compare_images(checker, grey, 3.0).flip_mean;
    const double near = compare_images(checker, grey, 12.0).flip_mean;
    const double standard = compare_images(checker, grey).flip_mean;
    std::printf("checkerboard against grey: FLIP %.4f at 3 ppd, %.4f at 12, %.4f at 67\n", close,
                near, standard);
    EXPECT_GT(close, 0.5);
    EXPECT_GT(close, near);
    EXPECT_GT(near, standard);
    EXPECT_LT(standard, 0.05);
}

TEST(ImageCompare, ADifferenceInOnePixelIsWorstThereAndFadesWithDistance) {
    const Image reference = flat(65, 65, make_float3(0.0f));
    Image test = reference;
    test.pixels[32 * 65 + 32] = make_float3(1.0f);
    const auto c = compare_images(reference, test);
    auto at = [&](unsigned x, unsigned y) { return c.flip[y * 65 + x]; };
    EXPECT_EQ(c.flip_max, at(32, 32));
    EXPECT_GT(at(32, 32), at(34, 32));
    EXPECT_GT(at(34, 32), at(38, 32));
    EXPECT_EQ(at(0, 0), 0.0f);  // beyond both filters' reach
    EXPECT_NEAR(at(30, 32), at(34, 32), 1e-6);  // symmetric
    EXPECT_NEAR(at(32, 30), at(34, 32), 1e-6);
}

TEST(ImageCompare, BadImagesAreRefusedByName) {
    EXPECT_THROW(compare_images(flat(4, 4, make_float3(0)), flat(4, 5, make_float3(0))), lucent::Error);
    Image nan = flat(4, 4, make_float3(0));
    nan.pixels[6].y = std::nanf("");
    try {
        compare_images(flat(4, 4, make_float3(0)), nan);
        FAIL() << "a NaN pixel was compared";
    } catch (const lucent::Error& e) {
        EXPECT_NE(std::string(e.what()).find("the test image has 1 pixels that are not finite"),
                  std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("x 2, y 1"), std::string::npos) << e.what();
    }
    EXPECT_THROW(compare_images(Image{}, Image{}), lucent::Error);
    EXPECT_THROW(lucent::scene::flip_error_map(flat(2, 2, make_float3(0)), flat(2, 2, make_float3(0)), 0.5),
                 lucent::Error);
}

class ImageRead : public ::testing::Test {
  protected:
    void SetUp() override {
        m_dir = std::filesystem::temp_directory_path() /
                ("lucent_image_read_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                 "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::create_directories(m_dir);
    }
    void TearDown() override { std::filesystem::remove_all(m_dir); }
    std::string path(const char* name) const { return (m_dir / name).string(); }
    std::filesystem::path m_dir;
};

TEST_F(ImageRead, WrittenImagesReadBackAsTheyWere) {
    Image image = flat(5, 3, make_float3(0.25f, 0.5f, 2.0f));
    image.pixels[1] = make_float3(0.0f, 0.125f, 9.5f);
    image.pixels[13] = make_float3(1.0f, 0.0f, 0.0f);
    for (const char* name : {"a.pfm", "a.exr"}) {
        lucent::scene::write_image(path(name), image);
        const Image back = lucent::scene::read_image(path(name));
        ASSERT_EQ(back.width, 5u) << name;
        ASSERT_EQ(back.height, 3u) << name;
        for (size_t i = 0; i < image.pixels.size(); ++i) {
            EXPECT_EQ(back.pixels[i].x, image.pixels[i].x) << name << " pixel " << i;
            EXPECT_EQ(back.pixels[i].z, image.pixels[i].z) << name << " pixel " << i;
        }
    }
    lucent::scene::write_image(path("a.png"), image);
    const Image png = lucent::scene::read_image(path("a.png"));
    EXPECT_NEAR(png.pixels[13].x, 1.0f, 1e-6);  // sRGB decoded
    EXPECT_NEAR(png.pixels[0].x, 0.25f, 0.01f);
}

TEST_F(ImageRead, MalformedFilesNameTheFileAndTheFault) {
    auto expect_error = [&](const char* name, const std::string& bytes, const char* fault) {
        std::ofstream(path(name), std::ios::binary) << bytes;
        try {
            lucent::scene::read_image(path(name));
            ADD_FAILURE() << name << " was read";
        } catch (const lucent::Error& e) {
            EXPECT_NE(std::string(e.what()).find(path(name)), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(fault), std::string::npos) << e.what();
        }
    };
    expect_error("short.pfm", "PF\n4 4\n-1.0\n" + std::string(20, '\0'), "but 20 bytes follow");
    expect_error("header.pfm", "P6\n4 4\n255\n", "not a PFM header");
    expect_error("huge.pfm", "PF\n100000 100000\n-1.0\n", "pixels; an image holds 1 to");
    expect_error("noise.png", "not a png at all", "cannot read the image");
    expect_error("a.txt", "x", "unknown extension");
    std::filesystem::create_directories(path("folder.png"));
    EXPECT_THROW(lucent::scene::read_image(path("folder.png")), lucent::Error);
    EXPECT_THROW(lucent::scene::read_image(path("missing.exr")), lucent::Error);
}

}  // namespace

namespace {

// A process ended by a signal while a registered temporary exists leaves no file behind
// (scene/temp_file_cleanup.h), and still ends by that signal.
TEST(TempFileCleanup, ASignalRemovesTheRegisteredTemporaryAndStillEndsTheProcess) {
    const std::string path = (std::filesystem::temp_directory_path() /
                              ("lucent_temp_cleanup_" + std::to_string(::getpid()))).string();
    const std::string kept = path + ".kept";
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        lucent::scene::remove_temp_files_on_signals();
        std::ofstream(path) << "partial image";
        std::ofstream(kept) << "an image written before";
        {
            lucent::scene::TempFileGuard released(kept);  // unregistered again: kept
        }
        lucent::scene::TempFileGuard guard(path);
        ::raise(SIGTERM);
        ::_exit(0);  // not reached
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
    EXPECT_FALSE(std::filesystem::exists(path));
    EXPECT_TRUE(std::filesystem::exists(kept));
    std::filesystem::remove(kept);
}

}  // namespace

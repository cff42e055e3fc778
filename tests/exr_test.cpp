// OpenEXR output: float pixels survive the round trip exactly (no 8-bit or half rounding).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "scene/exr_encoder.h"
#include "scene/image_io.h"

namespace {

TEST(Exr, WriteAndReadBackGivesTheSameFloats) {
    if (!lucent::scene::exr_supported()) GTEST_SKIP() << "built without OpenEXR";
    lucent::scene::Image image;
    image.width = 7;
    image.height = 3;
    for (unsigned i = 0; i < 21; ++i)
        image.pixels.push_back(make_float3(i * 0.1f, 1e-4f * i, 100.0f + i));  // beyond [0, 1]
    const std::string path =
        (std::filesystem::temp_directory_path() / "lucent_exr_test.exr").string();
    lucent::scene::write_image(path, image);
    auto back = lucent::scene::read_exr(path);
    std::filesystem::remove(path);
    ASSERT_EQ(back.width, 7u);
    ASSERT_EQ(back.height, 3u);
    for (unsigned i = 0; i < 21; ++i) {
        EXPECT_EQ(back.pixels[i].x, image.pixels[i].x) << i;
        EXPECT_EQ(back.pixels[i].y, image.pixels[i].y) << i;
        EXPECT_EQ(back.pixels[i].z, image.pixels[i].z) << i;
    }
}

}  // namespace

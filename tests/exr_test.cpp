// OpenEXR output: float pixels survive the round trip exactly (no 8-bit or half rounding).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "lucent/error.h"
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

namespace {

TEST(Exr, ExtraChannelsAndStringAttributesSurviveTheRoundTrip) {
    if (!lucent::scene::exr_supported()) GTEST_SKIP() << "built without OpenEXR";
    lucent::scene::Image image;
    image.width = 5;
    image.height = 2;
    lucent::scene::ExrExtras extras;
    extras.channels = {{"A", {}}, {"Albedo.R", {}}, {"Z", {}}};
    for (unsigned i = 0; i < 10; ++i) {
        image.pixels.push_back(make_float3(float(i), 0.5f, -1.0f));
        extras.channels[0].values.push_back(i % 2 ? 1.0f : 0.0f);
        extras.channels[1].values.push_back(0.01f * i);
        extras.channels[2].values.push_back(1e4f + i);
    }
    extras.attributes = {{"lucent.sample", "pathtracer"}, {"lucent.sets", "{\"seed\":\"3\"}"}};
    const std::string path =
        (std::filesystem::temp_directory_path() / "lucent_exr_layers_test.exr").string();
    lucent::scene::write_image(path, image, extras);
    const lucent::scene::ExrFile back = lucent::scene::read_exr_file(path);
    std::filesystem::remove(path);
    ASSERT_EQ(back.image.width, 5u);
    ASSERT_EQ(back.image.height, 2u);
    ASSERT_EQ(back.channels.size(), 3u);
    for (const auto& c : extras.channels) {
        ASSERT_TRUE(back.channels.count(c.name)) << c.name;
        EXPECT_EQ(back.channels.at(c.name), c.values) << c.name;
    }
    for (unsigned i = 0; i < 10; ++i) EXPECT_EQ(back.image.pixels[i].x, float(i));
    EXPECT_EQ(back.attributes.at("lucent.sample"), "pathtracer");
    EXPECT_EQ(back.attributes.at("lucent.sets"), "{\"seed\":\"3\"}");
}

TEST(Exr, ExtrasNeedAnExrAndChannelsOfThePixelCount) {
    lucent::scene::Image image;
    image.width = image.height = 2;
    image.pixels.assign(4, make_float3(0.0f));
    lucent::scene::ExrExtras extras;
    extras.channels = {{"A", {1, 1, 1, 1}}};
    const std::string dir = std::filesystem::temp_directory_path().string();
    try {
        lucent::scene::write_image(dir + "/lucent_exr_extras.png", image, extras);
        ADD_FAILURE() << "a PNG took extra channels";
    } catch (const lucent::Error& e) {
        EXPECT_NE(std::string(e.what()).find(".exr"), std::string::npos) << e.what();
    }
    if (!lucent::scene::exr_supported()) return;
    extras.channels[0].values.pop_back();
    EXPECT_THROW(lucent::scene::encode_exr("x.exr", image, extras), lucent::Error);
    extras.channels = {{"R", {1, 1, 1, 1}}};
    EXPECT_THROW(lucent::scene::encode_exr("x.exr", image, extras), lucent::Error);
}

}  // namespace

// OpenEXR output: float pixels survive the round trip exactly (no 8-bit or half rounding);
// input: files that are not regular or whose header claims more than they hold are refused.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "test_support.h"

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

/// An uncompressed scanline OpenEXR file of float R, G, B (OpenEXR's file layout: magic,
/// version, attributes, offset table, chunks) declaring `width` x `height` pixels but
/// holding only `lines` of them: what a damaged or hostile file looks like.
std::string exr_claiming(int width, int height, int lines) {
    std::string out("\x76\x2f\x31\x01\x02\x00\x00\x00", 8);
    auto put = [&](const void* p, size_t n) { out.append(static_cast<const char*>(p), n); };
    auto i32 = [&](int32_t v) { put(&v, 4); };
    auto attribute = [&](const char* name, const char* type, const std::string& value) {
        put(name, std::strlen(name) + 1);
        put(type, std::strlen(type) + 1);
        i32(int32_t(value.size()));
        out += value;
    };
    std::string channels;
    for (const char* c : {"B", "G", "R"}) {
        channels.append(c, 2);
        const int32_t fields[4] = {2 /* FLOAT */, 0 /* pLinear and reserved */, 1, 1};
        channels.append(reinterpret_cast<const char*>(fields), sizeof fields);
    }
    channels += '\0';
    const int32_t window[4] = {0, 0, width - 1, height - 1};
    const std::string box(reinterpret_cast<const char*>(window), sizeof window);
    const float one = 1, centre[2] = {0, 0};
    attribute("channels", "chlist", channels);
    attribute("compression", "compression", std::string(1, '\0'));
    attribute("dataWindow", "box2i", box);
    attribute("displayWindow", "box2i", box);
    attribute("lineOrder", "lineOrder", std::string(1, '\0'));
    attribute("pixelAspectRatio", "float", std::string(reinterpret_cast<const char*>(&one), 4));
    attribute("screenWindowCenter", "v2f", std::string(reinterpret_cast<const char*>(centre), 8));
    attribute("screenWindowWidth", "float", std::string(reinterpret_cast<const char*>(&one), 4));
    out += '\0';
    const uint64_t row = uint64_t(width) * 12, first = out.size() + 8 * uint64_t(height);
    for (int y = 0; y < height; ++y) {
        const uint64_t at = first + uint64_t(y) * (8 + row);
        put(&at, 8);
    }
    for (int y = 0; y < lines; ++y) {
        i32(y);
        i32(int32_t(row));
        out += std::string(row, '\0');
    }
    return out;
}

class ExrInput : public lucent_tests::TempDirTest {
  protected:
    static std::string error_of(const std::string& path) {
        try {
            lucent::scene::read_exr(path);
        } catch (const lucent::Error& e) {
            return e.what();
        }
        return "";
    }
};

TEST_F(ExrInput, HeadersThatClaimMoreThanTheFileHoldsAreRefusedBeforeReading) {
    if (!lucent::scene::exr_supported()) GTEST_SKIP() << "built without OpenEXR";
    // The writer is right: a whole 4 x 2 file reads.
    const std::string whole = write("whole.exr", exr_claiming(4, 2, 2));
    EXPECT_EQ(error_of(whole), "");
    EXPECT_EQ(lucent::scene::read_exr(whole).width, 4u);
    // 10^10 pixels in 1.2 MB asked for 120 GB (std::bad_alloc); 11,000 x 11,000 in 132 KB
    // took 1.4 GB before OpenEXR found the lines missing.
    const std::string huge = write("huge.exr", exr_claiming(100000, 100000, 1));
    EXPECT_EQ(error_of(huge), "cannot read '" + huge + "': it declares 100000 x 100000 pixels, "
                              "more than the 134217728 an image may have; resize it (or check "
                              "that the file is not damaged)");
    const std::string short_file = write("short.exr", exr_claiming(11000, 11000, 1));
    EXPECT_NE(error_of(short_file).find("it declares 11000 x 11000 pixels, which need at least "
                                        "1452176000 bytes, but the file has"),
              std::string::npos)
        << error_of(short_file);
    ASSERT_EQ(::mkfifo((dir / "pipe.exr").c_str(), 0600), 0);
    EXPECT_NE(error_of((dir / "pipe.exr").string()).find("this OpenEXR image is a FIFO"),
              std::string::npos);
}

}  // namespace


// Display frames (lucent/display.h): the 8-bit sRGB encoding is one definition everywhere
// (the formula, the host's table, the GPU's thresholds), and Context::display_frame gives
// the launch's output in it on every backend (LUCENT_TEST_BACKEND=cuda: on the GPU).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "lucent.h"
#include "samples/sample.h"
#include "scene/image_io.h"
#include "test_support.h"
#include "tests/programs/display_programs.h"

namespace {

using namespace lucent;
using namespace lucent_tests;

unsigned char table_encoding(float v) {
    const float4 p = make_float4(v, v, v, 0.f);
    unsigned char rgba[4];
    encode_srgb8_rgba(&p, 1, rgba);
    return rgba[0];
}

/// Values that probe every code's edges: each threshold and its float neighbours, specials.
std::vector<float> edge_values() {
    std::vector<float> v = {0.f, -0.f, -1.f, 1.f, 1.0000001f, 2.f, 1e30f,
                            std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity(),
                            std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::denorm_min(), 0.0031308f, 0.5f};
    const float* t = srgb8_thresholds();
    for (int k = 0; k < 255; ++k)
        for (int d = -2; d <= 2; ++d)
            v.push_back(std::bit_cast<float>(std::bit_cast<uint32_t>(t[k]) + uint32_t(d)));
    return v;
}

TEST(Srgb8, FormulaMatchesTheSrgbCurveAtKnownPoints) {
    EXPECT_EQ(srgb8_from_linear(0.f), 0);
    EXPECT_EQ(srgb8_from_linear(1.f), 255);
    EXPECT_EQ(srgb8_from_linear(0.5f), 188);      // 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354
    EXPECT_EQ(srgb8_from_linear(0.0031308f), 10);  // the linear segment's end: 0.04045
    EXPECT_EQ(srgb8_from_linear(-3.f), 0);
    EXPECT_EQ(srgb8_from_linear(7.f), 255);
    EXPECT_EQ(srgb8_from_linear(std::numeric_limits<float>::quiet_NaN()), 0);
}

TEST(Srgb8, ThresholdsRiseAndEachIsTheFirstFloatOfItsCode) {
    const float* t = srgb8_thresholds();
    for (int k = 0; k < 255; ++k) {
        if (k > 0) EXPECT_LT(t[k - 1], t[k]) << k;
        EXPECT_EQ(srgb8_from_linear(t[k]), k + 1) << k;
        const float below = std::bit_cast<float>(std::bit_cast<uint32_t>(t[k]) - 1);
        EXPECT_EQ(srgb8_from_linear(below), k) << k;
    }
}

TEST(Srgb8, TableEncodingEqualsTheFormulaForEveryProbedFloat) {
    for (float v : edge_values()) EXPECT_EQ(table_encoding(v), srgb8_from_linear(v)) << v;
    // A sweep over [0, 1]'s bit patterns, every 61st (about 17 million values).
    const uint32_t one = std::bit_cast<uint32_t>(1.0f);
    size_t mismatches = 0;
    for (uint32_t bits = 0; bits <= one; bits += 61) {
        const float v = std::bit_cast<float>(bits);
        mismatches += table_encoding(v) != srgb8_from_linear(v);
    }
    EXPECT_EQ(mismatches, 0u);
}

TEST(Srgb8, PngEncodingIsTheSameDefinition) {
    scene::Image image{3, 1, {make_float3(0.5f, 0.2f, 0.9f), make_float3(-1.f, 2.f, 0.01f),
                              make_float3(0.0031308f, 1.f, 0.f)}};
    const std::vector<unsigned char> rgb = scene::to_srgb8(image);
    for (size_t i = 0; i < image.pixels.size(); ++i) {
        EXPECT_EQ(rgb[3 * i + 0], srgb8_from_linear(image.pixels[i].x));
        EXPECT_EQ(rgb[3 * i + 1], srgb8_from_linear(image.pixels[i].y));
        EXPECT_EQ(rgb[3 * i + 2], srgb8_from_linear(image.pixels[i].z));
    }
}

/// A context whose launch copies `values` (padded to width x height) into a 2D output.
struct CopyScene {
    CopyScene(unsigned width, unsigned height, const std::vector<float>& values)
        : ctx(test_context_options()), width(width), height(height) {
        std::vector<float4> pixels(size_t(width) * height);
        for (size_t i = 0; i < pixels.size(); ++i) {
            const auto at = [&](size_t k) { return values[k % values.size()]; };
            pixels[i] = make_float4(at(3 * i), at(3 * i + 1), at(3 * i + 2), 1.f);
        }
        source = ctx.create_buffer<float4>(BufferType::kInput, width, height);
        source->upload(pixels);
        output = ctx.create_buffer<float4>(BufferType::kOutput, width, height);
        ctx["source"] = source;
        ctx["image"] = output;
        ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(dt_copy_image)));
        ctx.launch(0, width, height);
        expected.resize(pixels.size() * 4);
        encode_srgb8_rgba(pixels.data(), pixels.size(), expected.data());
    }
    Context ctx;
    unsigned width, height;
    std::shared_ptr<Buffer> source, output;
    std::vector<unsigned char> expected;  // the host's encoding of the values
};

TEST(DisplayFrame, EqualsTheHostEncodingOfTheOutputBitForBit) {
    CopyScene s(67, 41, edge_values());  // odd sizes: rows are not multiples of a block
    const std::shared_ptr<DisplayFrame> frame = s.ctx.display_frame(*s.output);
    EXPECT_EQ(frame->width(), 67u);
    EXPECT_EQ(frame->height(), 41u);
    EXPECT_EQ(frame->on_device(), test_backend() == BackendKind::kCuda);
    const std::vector<unsigned char> rgba = frame->rgba();
    ASSERT_EQ(rgba.size(), s.expected.size());
    size_t differing = 0;
    for (size_t i = 0; i < rgba.size(); ++i) differing += rgba[i] != s.expected[i];
    EXPECT_EQ(differing, 0u);
    for (size_t i = 3; i < rgba.size(); i += 4) ASSERT_EQ(rgba[i], 255);
}

TEST(DisplayFrame, OutlivesItsContext) {
    std::shared_ptr<DisplayFrame> frame;
    std::vector<unsigned char> expected;
    {
        CopyScene s(16, 8, {0.25f, 0.5f, 0.75f, 0.125f});
        frame = s.ctx.display_frame(*s.output);
        expected = s.expected;
    }
    EXPECT_EQ(frame->rgba(), expected);
}

TEST(DisplayFrame, FollowsAHostWriteAfterTheLaunch) {
    CopyScene s(4, 2, {0.5f});
    std::vector<float4> white(8, make_float4(1.f, 1.f, 1.f, 1.f));
    s.output->upload(white);  // the host copy is now the newest
    const std::vector<unsigned char> rgba = s.ctx.display_frame(*s.output)->rgba();
    EXPECT_EQ(rgba, std::vector<unsigned char>(32, 255));
}

TEST(DisplayFrame, ABufferOfAnotherShapeOrContextIsAClearError) {
    CopyScene s(4, 2, {0.5f});
    auto flat = s.ctx.create_buffer<float4>(BufferType::kOutput, 8);
    auto floats = s.ctx.create_buffer<float>(BufferType::kOutput, 4, 2);
    Context other(test_context_options());
    auto foreign = other.create_buffer<float4>(BufferType::kOutput, 4, 2);
    expect_error([&] { s.ctx.display_frame(*flat); }, {"not a 2D buffer of float4"}, "1D");
    expect_error([&] { s.ctx.display_frame(*floats); }, {"not a 2D buffer of float4"}, "float");
    expect_error([&] { s.ctx.display_frame(*foreign); }, {"belongs to another Context"}, "other");
}

TEST(DisplayFrame, SessionsGiveDisplayFramesEqualToTheirImages) {
    for (const char* name : {"whitted", "pathtracer", "fog", "direct", "radiosity"}) {
        samples::RenderSettings settings;
        settings.width = 40;
        settings.height = 30;
        settings.backend = test_backend();
        settings.threads = 2;
        const samples::Sample& sample = samples::find_sample(name);
        const samples::FrameResult image = sample.open(settings)->frame();
        settings.display_frames = true;
        const samples::FrameResult shown = sample.open(settings)->frame();
        ASSERT_TRUE(shown.display) << name;
        EXPECT_TRUE(shown.image.pixels.empty()) << name;
        const std::vector<unsigned char> rgb = scene::to_srgb8(image.image);
        const std::vector<unsigned char> rgba = shown.display->rgba();
        ASSERT_EQ(rgba.size(), rgb.size() / 3 * 4) << name;
        size_t differing = 0;
        for (size_t i = 0; i < rgb.size() / 3; ++i)
            for (size_t c = 0; c < 3; ++c) differing += rgba[4 * i + c] != rgb[3 * i + c];
        EXPECT_EQ(differing, 0u) << name;
    }
}

}  // namespace

namespace {

// GlTexture has one definition whatever the build: where CUDA-OpenGL interop cannot be made
// (no CUDA backend, no driver) it throws an error saying so; where it can, a host frame is
// refused with the fix (upload its rgba()).
TEST(GlTexture, SaysWhyItCannotCopyAFrame) {
    const std::vector<float4> pixels(4, make_float4(0.5f, 0.5f, 0.5f, 1));
    const auto frame = lucent::DisplayFrame::from_linear(2, 2, pixels.data());
    try {
        lucent::GlTexture texture(1);
        try {
            texture.copy_from(*frame);
            ADD_FAILURE() << "a host frame was copied through CUDA-OpenGL interop";
        } catch (const lucent::Error& e) {
            EXPECT_NE(std::string(e.what()).find("upload its rgba()"), std::string::npos)
                << e.what();
        }
    } catch (const lucent::Error& e) {
        EXPECT_NE(std::string(e.what()).find("CUDA-OpenGL interop"), std::string::npos)
            << e.what();
    }
}

}  // namespace

// AOVs and the edge-avoiding à-trous denoiser (Dammertz et al. 2010): the G-buffer's layers of
// the Cornell box hold its materials and geometry, the denoiser brings a 4-spp path-traced
// Cornell box much nearer a high-spp reference, and it keeps a hard edge between two
// surfaces of different normals while flattening the noise on each side.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "lucent/context.h"
#include "samples/aov.h"
#include "samples/atrous_denoiser.h"
#include "samples/sample.h"
#include "samples/settings_error.h"
#include "scene/image_compare.h"
#include "tests/test_support.h"

namespace {

using lucent::samples::RenderResult;
using lucent::samples::RenderSettings;

RenderSettings cornell(unsigned size, unsigned spp) {
    RenderSettings settings;
    settings.width = settings.height = size;
    settings.backend = lucent_tests::test_backend();  // LUCENT_TEST_BACKEND=cuda: the GPU
    settings.threads = 2;
    settings.spp = spp;
    return settings;
}

const std::vector<float>& channel(const RenderResult& r, const std::string& name) {
    for (const auto& c : r.aovs)
        if (c.name == name) return c.values;
    ADD_FAILURE() << "no channel " << name;
    static const std::vector<float> none;
    return none;
}

TEST(Aov, NamesParseAndBadOnesNameTheFlagTheValueAndTheAcceptedOnes) {
    using lucent::samples::parse_aovs;
    const auto all = parse_aovs("--aov", "albedo,normal,depth,position,instance");
    EXPECT_TRUE(all.albedo && all.normal && all.depth && all.position && all.instance);
    const auto one = parse_aovs("--aov", "depth");
    EXPECT_TRUE(one.depth);
    EXPECT_FALSE(one.albedo || one.normal || one.position || one.instance);
    for (const char* bad : {"albdo", "", "albedo,", "albedo,,depth", "rgb"}) {
        try {
            parse_aovs("--aov", bad);
            ADD_FAILURE() << "accepted '" << bad << "'";
        } catch (const lucent::samples::SettingsError& e) {
            const std::string m = e.what();
            EXPECT_NE(m.find(std::string("--aov '") + bad + "'"), std::string::npos) << m;
            EXPECT_NE(m.find("accepted: albedo, normal, depth, position, instance"),
                      std::string::npos)
                << m;
        }
    }
    try {
        parse_aovs("--aov", "albdo");
    } catch (const lucent::samples::SettingsError& e) {
        EXPECT_NE(std::string(e.what()).find("did you mean 'albedo'"), std::string::npos);
    }
}

TEST(Aov, CornellGBufferHoldsTheMaterialsAndTheGeometry) {
    RenderSettings settings = cornell(32, 1);
    settings.aovs = lucent::samples::parse_aovs("--aov", "albedo,normal,depth,position,instance");
    settings.alpha = true;
    const RenderResult r = lucent::samples::find_sample("pathtracer").render(settings);
    ASSERT_EQ(r.aovs.size(), 1u + 3 + 3 + 3 + 1 + 1);
    const auto& a = channel(r, "A");
    const auto& red = channel(r, "Albedo.R");
    const auto& green = channel(r, "Albedo.G");
    const auto& nx = channel(r, "Nx");
    const auto& ny = channel(r, "Ny");
    const auto& nz = channel(r, "Nz");
    const auto& z = channel(r, "Z");
    const auto& instance = channel(r, "InstanceId");
    ASSERT_EQ(a.size(), 32u * 32u);
    // Coverage is 1 exactly where the G-buffer found a surface: a unit normal, a depth in
    // front of the camera and an instance; 0 with the background's values elsewhere.
    size_t covered = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        ASSERT_TRUE(a[i] == 0.0f || a[i] == 1.0f) << i;
        if (a[i] == 1.0f) {
            ++covered;
            EXPECT_NEAR(nx[i] * nx[i] + ny[i] * ny[i] + nz[i] * nz[i], 1.0f, 1e-4f) << i;
            EXPECT_GT(z[i], 0.0f) << i;
            EXPECT_GE(instance[i], 0.0f) << i;
        } else {
            EXPECT_EQ(z[i], 0.0f) << i;
            EXPECT_EQ(instance[i], -1.0f) << i;
        }
    }
    // The box fills most of the view; its open front shows some background.
    EXPECT_GT(covered, a.size() * 3 / 4);
    EXPECT_LT(covered, a.size());
    // Along the middle row, the first surface is the red wall and the last the green one
    // (Cornell box data: Kd 0.63/0.065/0.05 and 0.14/0.45/0.091).
    size_t left = 16 * 32, right = 16 * 32 + 31;
    while (a[left] == 0.0f) ++left;
    while (a[right] == 0.0f) --right;
    EXPECT_GT(red[left], 0.5f);
    EXPECT_LT(green[left], 0.1f);
    EXPECT_LT(red[right], 0.2f);
    EXPECT_GT(green[right], 0.4f);
    // Facing the camera: the two walls' normals point at each other, along x.
    EXPECT_LT(nx[left] * nx[right], -0.9f);
    // The boxes are meshes of their own: more than one instance is seen.
    float lo = 1e30f, hi = -1e30f;
    for (size_t i = 0; i < a.size(); ++i)
        if (a[i] == 1.0f) lo = std::min(lo, instance[i]), hi = std::max(hi, instance[i]);
    EXPECT_LT(lo, hi);
}

TEST(Aov, EverySampleWithAGBufferWritesItsLayersAndDenoises) {
    for (const lucent::samples::Sample* sample : lucent::samples::all_samples()) {
        if (!sample->writes_aovs()) continue;
        RenderSettings settings = cornell(16, 1);
        settings.aovs.depth = settings.aovs.albedo = true;
        settings.alpha = settings.denoise = true;
        const RenderResult r = sample->render(settings);
        ASSERT_EQ(r.aovs.size(), 5u) << sample->name;
        EXPECT_EQ(r.aovs[0].name, "A") << sample->name;
        size_t covered = 0;
        for (size_t i = 0; i < r.aovs[0].values.size(); ++i)
            if (r.aovs[0].values[i] == 1.0f) {
                ++covered;
                EXPECT_GT(channel(r, "Z")[i], 0.0f) << sample->name << " " << i;
            }
        EXPECT_GT(covered, 16u * 16u / 2) << sample->name;
        EXPECT_EQ(r.image.pixels.size(), 16u * 16u) << sample->name;
        EXPECT_TRUE(r.camera.has_value()) << sample->name;
    }
}

TEST(Denoise, BringsAFourSppCornellBoxMuchNearerTheReference) {
    const auto& pathtracer = lucent::samples::find_sample("pathtracer");
    const RenderResult reference = pathtracer.render(cornell(64, 256));
    const RenderResult noisy = pathtracer.render(cornell(64, 4));
    RenderSettings settings = cornell(64, 4);
    settings.denoise = true;
    // At 64x64 two passes do best (taps 1 and 2 pixels apart); the wider passes of the default
    // blur the soft shadows of so small an image (docs/samples.md).
    settings.denoise_options.iterations = 2;
    const RenderResult denoised = pathtracer.render(settings);
    const auto before = lucent::scene::compare_images(reference.image, noisy.image);
    const auto after = lucent::scene::compare_images(reference.image, denoised.image);
    EXPECT_LT(after.relmse, before.relmse / 3) << before.relmse << " -> " << after.relmse;
    EXPECT_LT(after.flip_mean, before.flip_mean) << before.flip_mean << " -> " << after.flip_mean;
    bool has_stage = false;
    for (const auto& s : denoised.stages) has_stage = has_stage || s.name == "denoise";
    EXPECT_TRUE(has_stage);
}

/// A synthetic G-buffer: the left half a plane facing +z, the right half a plane facing +x,
/// both at depth 1, white albedo; the colour 0.2 on the left and 0.8 on the right with
/// uniform noise of +-0.15.
TEST(Denoise, KeepsAHardEdgeBetweenTwoNormalsAndFlattensTheNoise) {
    constexpr unsigned w = 64, h = 32;
    lucent::Context ctx(lucent_tests::test_context_options());
    auto image = [&] { return ctx.create_buffer<float4>(lucent::BufferType::kInputOutput, w, h); };
    lucent::samples::AtrousDenoiser::Guides guides{image(), image(), image()};
    auto colour = image();
    std::vector<float4> albedo(w * h), normal(w * h), position(w * h), noisy(w * h);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> noise(-0.15f, 0.15f);
    for (unsigned y = 0; y < h; ++y)
        for (unsigned x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            const bool left = x < w / 2;
            albedo[i] = make_float4(1.0f, 1.0f, 1.0f, 1.0f);
            normal[i] = left ? make_float4(0.0f, 0.0f, 1.0f, 0.0f) : make_float4(1.0f, 0.0f, 0.0f, 1.0f);
            // Each half a plane through its points: z = 0 on the left, x = w/2 on the right.
            position[i] = left ? make_float4(float(x), float(y), 0.0f, 1.0f)
                               : make_float4(float(w / 2), float(y), float(x), 1.0f);
            const float v = (left ? 0.2f : 0.8f) + noise(rng);
            noisy[i] = make_float4(v, v, v, 1.0f);
        }
    guides.albedo->upload(albedo);
    guides.normal->upload(normal);
    guides.position->upload(position);
    colour->upload(noisy);
    lucent::samples::AtrousDenoiser denoiser(ctx, 0, guides, colour, w, h);
    double ms = 0;
    // A pixel's footprint of 1 at depth 1: the positions above are in pixels.
    const lucent::Buffer& out = denoiser.run(lucent::samples::DenoiseOptions{}, 1.0f, ms);
    const float4* p = out.data<float4>();
    // The columns on either side of the edge keep their side's value; every pixel is much
    // nearer its side's value than the noise left it.
    double error_before = 0, error_after = 0;
    for (unsigned y = 0; y < h; ++y)
        for (unsigned x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            const float truth = x < w / 2 ? 0.2f : 0.8f;
            error_before += (noisy[i].x - truth) * (noisy[i].x - truth);
            error_after += (p[i].x - truth) * (p[i].x - truth);
            if (x == w / 2 - 1 || x == w / 2) {
                EXPECT_NEAR(p[i].x, truth, 0.05f) << x << "," << y;
            }
        }
    EXPECT_LT(error_after, error_before / 10) << error_before << " -> " << error_after;

    // The same passes with every edge-stopping weight made flat blur across the edge: what
    // the check above guards against is real.
    lucent::samples::DenoiseOptions flat;
    flat.sigma_colour = flat.sigma_normal = flat.sigma_position = 1e30f;
    const float4* blurred = denoiser.run(flat, 1.0f, ms).data<float4>();
    const size_t edge = size_t(h / 2) * w + w / 2;
    EXPECT_GT(std::fabs(blurred[edge].x - 0.8f), 0.1f) << blurred[edge].x;
    EXPECT_GT(std::fabs(blurred[edge - 1].x - 0.2f), 0.1f) << blurred[edge - 1].x;
}

}  // namespace

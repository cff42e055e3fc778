// The viewer's temporal denoiser (SVGF, Schied et al. 2017): a resting camera's history
// brings the path-traced Cornell box nearer a high-spp reference frame by frame, which
// the first frame (no history: the spatial filter alone) cannot; and a camera move keeps the
// history of every pixel whose surface point the previous frame saw, and restarts the
// pixels it uncovers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <optional>
#include <random>
#include <vector>

#include "lucent/context.h"
#include "samples/common/camera.h"
#include "samples/sample.h"
#include "samples/svgf_denoiser.h"
#include "scene/image_compare.h"
#include "test_support.h"

namespace {

using lucent::samples::RenderSettings;

RenderSettings cornell(unsigned size, unsigned spp) {
    RenderSettings settings;
    settings.width = settings.height = size;
    settings.backend = lucent_tests::test_backend();  // LUCENT_TEST_BACKEND=cuda: the GPU
    settings.threads = 2;
    settings.spp = spp;
    return settings;
}

TEST(Svgf, ARestingCameraConvergesTowardTheReferenceFasterThanWithoutHistory) {
    const auto& pathtracer = lucent::samples::find_sample("pathtracer");
    const auto reference = pathtracer.render(cornell(32, 512)).image;
    auto session = pathtracer.open(cornell(32, 0));
    ASSERT_TRUE(session->denoises());
    session->set_denoiser(lucent::samples::ViewDenoiser::kSvgf);
    std::vector<double> error;  // relative MSE after frame 1, 2, ...
    for (int f = 0; f < 16; ++f) {
        const auto frame = session->frame();
        EXPECT_EQ(frame.samples, unsigned(f + 1));
        error.push_back(lucent::scene::compare_images(reference, frame.image).relmse);
    }
    // Frame 1 has no history: what every frame would be without temporal accumulation.
    // Frame 1 has no history: what every frame would be without temporal accumulation
    // (measured: relative MSE 0.42, then 0.031 after 4 frames and 0.02-0.04 after 8-16).
    EXPECT_LT(error[3], error[0] / 4) << error[0] << " -> " << error[3];
    double last4 = 0;
    for (int f = 12; f < 16; ++f) last4 += error[size_t(f)] / 4;
    EXPECT_LT(last4, error[0] / 8) << error[0] << " -> " << last4;
}

TEST(Svgf, TheViewersDenoisedMegakernelCompilesForSm90) {
#if !LUCENT_HAVE_CUDA
    GTEST_SKIP() << "built without the CUDA toolkit: no megakernel to compile";
#else
    ::setenv("LUCENT_CACHE_DIR", "off", 1);  // a real NVRTC compile, not a cache hit
    RenderSettings settings = cornell(8, 0);
    settings.backend = lucent::BackendKind::kCpu;  // the CPU runs it; NVRTC compiles it too
    settings.jit_check_sm = 90;
    auto session = lucent::samples::find_sample("pathtracer").open(settings);
    for (auto d : {lucent::samples::ViewDenoiser::kSvgf, lucent::samples::ViewDenoiser::kAtrous}) {
        session->set_denoiser(d);
        lucent::samples::FrameResult frame;
        ASSERT_NO_THROW(frame = session->frame()) << lucent::samples::view_denoiser_name(d);
        EXPECT_EQ(frame.image.pixels.size(), 64u);
        // The first switch added the G-buffer and both denoisers: a megakernel with them.
        if (d == lucent::samples::ViewDenoiser::kSvgf) EXPECT_GT(frame.report.jit_ms, 0.0);
    }
#endif
}

// A synthetic scene the test ray-casts itself: a wall at z = -10 and, in front of it, a
// 2x2 square at z = -5 (instance 1), seen from eye (0, 0, 0) down -z and then from eye
// (0.8, 0, 0), which uncovers wall the square hid.
struct Hit {
    int instance = -1;
    float3 point{};
};

Hit cast(float3 eye, float3 direction) {
    Hit hit;
    const float t_square = (-5.0f - eye.z) / direction.z;
    const float3 s = eye + t_square * direction;
    if (t_square > 0 && std::fabs(s.x) < 1.0f && std::fabs(s.y) < 1.0f) return {1, s};
    const float t_wall = (-10.0f - eye.z) / direction.z;
    if (t_wall > 0) hit = {0, eye + t_wall * direction};
    return hit;
}

constexpr unsigned kW = 40, kH = 32;
constexpr float kTan = 0.5f;  // half the image's height at depth 1

sample_common::PinholeCamera camera_at(float3 eye) {
    return {eye, make_float3(kTan * kW / kH, 0, 0), make_float3(0, kTan, 0), make_float3(0, 0, -1)};
}

Hit pixel_hit(const sample_common::PinholeCamera& c, unsigned x, unsigned y) {
    return cast(c.eye, sample_common::pixel_centre_direction(c, make_uint3(x, y, 0),
                                                             make_uint3(kW, kH, 1)));
}

TEST(Svgf, ACameraMoveKeepsTheHistoryOfSurfacesSeenInBothFramesAndRestartsUncoveredOnes) {
    lucent::Context ctx(lucent_tests::test_context_options());
    auto image = [&] {
        return ctx.create_buffer<float4>(lucent::BufferType::kInputOutput, kW, kH);
    };
    lucent::samples::AtrousDenoiser::Guides guides{image(), image(), image()};
    auto colour = image();
    lucent::samples::SvgfDenoiser svgf(ctx, 0, guides, colour, kW, kH);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> noise(-0.1f, 0.1f);
    auto render = [&](const sample_common::PinholeCamera& c) {
        std::vector<float4> albedo(kW * kH), normal(kW * kH), position(kW * kH), noisy(kW * kH);
        for (unsigned y = 0; y < kH; ++y)
            for (unsigned x = 0; x < kW; ++x) {
                const size_t i = size_t(y) * kW + x;
                const Hit h = pixel_hit(c, x, y);
                ASSERT_GE(h.instance, 0);
                albedo[i] = make_float4(0.5f, 0.5f, 0.5f, 1.0f);
                normal[i] = make_float4(0.0f, 0.0f, 1.0f, float(h.instance));
                position[i] = make_float4(h.point, c.eye.z - h.point.z);
                const float v = 0.25f + noise(rng);
                noisy[i] = make_float4(v, v, v, 1.0f);
            }
        guides.albedo->upload(albedo);
        guides.normal->upload(normal);
        guides.position->upload(position);
        colour->upload(noisy);
        double ms = 0;
        svgf.run(c, lucent::samples::SvgfOptions{}, ms);
    };
    const auto a = camera_at(make_float3(0, 0, 0)), b = camera_at(make_float3(0.8f, 0, 0));
    for (int f = 0; f < 3; ++f) render(a);  // a history of 3 frames
    render(b);
    const float4* integrated = svgf.integrated_colour().data<float4>();

    // Where B's pixel's point lies in A's image (pixel centres at integers), and whether the
    // four pixels of A around it saw the same surface there.
    unsigned kept = 0, restarted = 0;
    for (unsigned y = 0; y < kH; ++y)
        for (unsigned x = 0; x < kW; ++x) {
            const Hit h = pixel_hit(b, x, y);
            const float depth = -h.point.z;
            const float px = (h.point.x / depth / (kTan * kW / kH) + 1) * 0.5f * kW - 0.5f;
            const float py = (1 - h.point.y / depth / kTan) * 0.5f * kH - 0.5f;
            const int x0 = int(std::floor(px)), y0 = int(std::floor(py));
            if (x0 < 0 || y0 < 0 || x0 + 1 >= int(kW) || y0 + 1 >= int(kH)) continue;
            int same = 0;
            for (int t = 0; t < 4; ++t)
                same += pixel_hit(a, unsigned(x0 + (t & 1)), unsigned(y0 + (t >> 1))).instance ==
                        h.instance;
            const float length = integrated[size_t(y) * kW + x].w;
            if (same == 4) {
                EXPECT_NEAR(length, 4.0f, 1e-4f) << x << "," << y;
                ++kept;
            } else if (same == 0) {
                EXPECT_EQ(length, 1.0f) << x << "," << y;
                ++restarted;
            }
        }
    EXPECT_GT(kept, kW * kH / 2);
    EXPECT_GT(restarted, 10u);
}

}  // namespace

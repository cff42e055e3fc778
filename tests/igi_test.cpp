// The IGI sample (IGI paper §4): VPLs light what the lights cannot see, Eq. (1)'s indirect term
// agrees with a brute-force reference, and each of the paper's accelerations (imperfect
// visibility, downsampling, interleaving) stays close to the canonical image.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "samples/sample.h"
#include "samples/igi/igi_frames.h"
#include "samples/igi/igi_programs.h"
#include "samples/settings_error.h"
#include "scene/scene.h"
#include "tests/reference_tracer.h"
#include "tests/test_support.h"

namespace {

using lucent::samples::RenderResult;
using lucent::samples::RenderSettings;

RenderResult render(const std::map<std::string, std::string>& sets, unsigned size = 64,
                    const std::string& scene = "", bool layers = false) {
    RenderSettings settings;
    settings.width = settings.height = size;
    settings.backend = lucent_tests::test_backend();  // LUCENT_TEST_BACKEND=cuda: the GPU
    settings.sets = sets;
    settings.scene = scene;
    settings.keep_layers = layers;
    return lucent::samples::find_sample("igi").render(settings);
}

float brightness(const RenderResult& r, float fx, float fy) {
    const float3 p =
        r.image.pixels[size_t(fy * r.image.height) * r.image.width + size_t(fx * r.image.width)];
    return p.x + p.y + p.z;
}

double sum(const lucent::scene::Image& image) {
    double s = 0;
    for (const float3& p : image.pixels) s += p.x + p.y + p.z;
    return s;
}

/// Root-mean-square difference of two images over the mean brightness of the first.
double relative_rms(const lucent::scene::Image& reference, const lucent::scene::Image& other) {
    double squared = 0;
    for (size_t i = 0; i < reference.pixels.size(); ++i) {
        const float3 d = reference.pixels[i] - other.pixels[i];
        squared += dot(d, d) / 3.0;
    }
    const double mean = sum(reference) / (3.0 * reference.pixels.size());
    return std::sqrt(squared / reference.pixels.size()) / mean;
}

TEST(Igi, SmoothingIsZeroThenQuadraticThenOne) {
    EXPECT_EQ(igi::smoothing(1.0f, 2.0f, 0.5f), 0.0f);
    EXPECT_FLOAT_EQ(igi::smoothing(1.0f, 2.0f, 1.5f), 0.25f);
    EXPECT_EQ(igi::smoothing(1.0f, 2.0f, 2.5f), 1.0f);
}

TEST(Igi, HaltonIsTheRadicalInverse) {
    // phi_b(i) = sum_k d_k b^-(k+1) for i = sum_k d_k b^k, checked digit by digit.
    for (unsigned base : {2u, 3u, 5u, 7u})
        for (unsigned i = 0; i < 200; ++i) {
            double expected = 0, scale = 1.0 / base;
            for (unsigned n = i; n > 0; n /= base, scale /= base) expected += (n % base) * scale;
            EXPECT_NEAR(igi::halton(i, base), expected, 1e-6) << "base " << base << " i " << i;
        }
    EXPECT_FLOAT_EQ(igi::halton(1, 2), 0.5f);
    EXPECT_FLOAT_EQ(igi::halton(3, 2), 0.75f);
    EXPECT_FLOAT_EQ(igi::halton(2, 3), 2.0f / 3.0f);
}

TEST(Igi, VplsLightWhatThePointLightCannotSee) {
    // The short block's front face is turned away from the ceiling light: black with direct
    // light only (min_d = 10 scene sizes bounds away every VPL), lit by the VPLs otherwise.
    const RenderResult direct_only = render({{"min_d", "10"}}, 64, "cornell-point");
    const RenderResult global = render({{"vpls", "180"}, {"min_d", "0.05"}}, 64, "cornell-point");
    EXPECT_EQ(brightness(direct_only, 0.6f, 0.85f), 0.0f);
    EXPECT_GT(brightness(global, 0.6f, 0.85f), 1e-4f);
    EXPECT_EQ(global.report.exception_count(), 0u);
}

TEST(Igi, AreaLightsBecomeGridsOfPointEmitters) {
    // `cornell` has only its ceiling area light: it lights the floor directly and the
    // short block's front face through VPLs; more emitters change the picture only a little.
    const RenderResult coarse = render({{"area_samples", "2"}});
    const RenderResult fine = render({{"area_samples", "6"}});
    EXPECT_GT(brightness(fine, 0.5f, 0.97f), 0.1f) << "the floor is lit";
    EXPECT_GT(brightness(fine, 0.6f, 0.85f), 1e-4f) << "the VPLs light the block";
    EXPECT_LT(relative_rms(fine.image, coarse.image), 0.15);
    EXPECT_NEAR(sum(coarse.image) / sum(fine.image), 1.0, 0.05) << "the same power";
}

TEST(Igi, IndirectAgreesWithABruteForceReference) {
    // Canonical IGI with many VPLs and exact visibility against a path-traced one-bounce
    // reference computed here without the engine, at the same primary hits (the G-buffer).
    // Eq. (1)'s bound is kept small (0.5% of the scene) so that its bias stays small too.
    const RenderResult igi = render({{"vpls", "8192"}, {"min_d", "0.005"}, {"bounces", "1"}}, 24,
                                    "cornell-point", /*layers=*/true);
    const lucent::scene::Scene scene = lucent::scene::load_scene("cornell-point");
    lucent_tests::ReferenceTracer tracer(scene);
    const auto& position = igi.layers.at("position");
    const auto& normal = igi.layers.at("normal");
    const auto& indirect = igi.layers.at("indirect");
    std::mt19937 rng(7);
    double igi_total = 0, reference_total = 0;
    // Quadrants of the image: each sum must agree, not only the whole.
    double igi_quadrant[4] = {}, reference_quadrant[4] = {};
    for (unsigned y = 0; y < position.height; ++y)
        for (unsigned x = 0; x < position.width; ++x) {
            const size_t i = size_t(y) * position.width + x;
            if (dot(normal.pixels[i], normal.pixels[i]) < 0.5f) continue;  // background
            const float3 e = tracer.one_bounce_irradiance(position.pixels[i], normal.pixels[i],
                                                          1024, 0.05f, rng);
            const double ref = e.x + e.y + e.z;
            const double got = indirect.pixels[i].x + indirect.pixels[i].y + indirect.pixels[i].z;
            const int q = (x * 2 / position.width) + 2 * (y * 2 / position.height);
            igi_total += got;
            reference_total += ref;
            igi_quadrant[q] += got;
            reference_quadrant[q] += ref;
        }
    ASSERT_GT(reference_total, 0.0);
    EXPECT_NEAR(igi_total / reference_total, 1.0, 0.03);
    for (int q = 0; q < 4; ++q)
        EXPECT_NEAR(igi_quadrant[q] / reference_quadrant[q], 1.0, 0.05) << "quadrant " << q;
}

TEST(Igi, ImperfectVisibilityStaysCloseToCanonical) {
    // Seed §4.1: VPL shadow rays against boxes: 1, the scene BVH's leaf boxes
    // (Occlusion::kLeafBoxes); 2, the paper's second graph of one box per triangle (a second
    // root and ray type); or 3, no shadow rays but a depth map per VPL.
    const RenderResult exact = render({{"imperfect_visibility", "0"}});
    for (const char* form : {"1", "2", "3"}) {
        const RenderResult boxes = render({{"imperfect_visibility", form}});
        EXPECT_EQ(boxes.report.exception_count(), 0u) << form;
        EXPECT_GT(brightness(boxes, 0.6f, 0.85f), 0.0f) << "VPL light still arrives; " << form;
        EXPECT_LT(relative_rms(exact.image, boxes.image), 0.03) << form;
        EXPECT_NE(sum(exact.image), sum(boxes.image)) << "the boxes change something; " << form;
    }
}

TEST(Igi, VisibilityMapTexelsAndLookupsAgree) {
    // A map's texel (i, j) is traced in vpl_map_direction; a lookup towards that direction
    // lands on the texel's centre, so it reads that texel alone, whatever the VPL's normal.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    constexpr unsigned kSize = 16;
    for (int trial = 0; trial < 20; ++trial) {
        const float3 n = normalize(make_float3(unit(rng), unit(rng), unit(rng)));
        const igi::VplFrame f = igi::vpl_frame(n);
        EXPECT_NEAR(dot(f.t, f.b), 0.0f, 1e-5f);
        EXPECT_NEAR(dot(f.t, n), 0.0f, 1e-5f);
        EXPECT_NEAR(dot(cross(f.t, f.b), n), 1.0f, 1e-5f) << "right-handed";
        for (unsigned j = 0; j < kSize; ++j)
            for (unsigned i = 0; i < kSize; ++i) {
                const float3 w = igi::vpl_map_direction(f, i, j, kSize);
                EXPECT_NEAR(length(w), 1.0f, 1e-5f);
                EXPECT_GE(dot(w, n), -1e-6f) << "in the VPL's hemisphere";
                const float u = 2.0f * (i + 0.5f) / kSize - 1.0f;
                const float v = 2.0f * (j + 0.5f) / kSize - 1.0f;
                if (u * u + v * v > 1.0f) continue;  // outside the disc: the rim's direction
                const float s = 1.0f / (1.0f + dot(w, n));
                EXPECT_NEAR(dot(w, f.t) * s, u, 1e-5f) << i << "," << j;
                EXPECT_NEAR(dot(w, f.b) * s, v, 1e-5f) << i << "," << j;
            }
    }
}

TEST(Igi, VisibilityMapsCastShadowsThatSharpenWithResolution) {
    // The maps stand in for shadow rays: at 64 texels square the image is near the exact
    // one, and further from it at 4, so the lookups do shadow (a lookup that saw everything
    // would give both the same image).
    const RenderResult exact = render({{"imperfect_visibility", "0"}});
    const RenderResult fine = render({{"imperfect_visibility", "3"}, {"visibility_map", "64"}});
    const RenderResult coarse = render({{"imperfect_visibility", "3"}, {"visibility_map", "4"}});
    const double fine_error = relative_rms(exact.image, fine.image);
    const double coarse_error = relative_rms(exact.image, coarse.image);
    EXPECT_LT(fine_error, 0.01);
    EXPECT_GT(coarse_error, 2.0 * fine_error);
}

TEST(Igi, DownsamplingStaysCloseToCanonical) {
    // Seed §4.2: indirect at 1/N resolution, joint bilateral upsampling (Eq. 2).
    const RenderResult canonical = render({});
    for (const char* n : {"2", "4"}) {
        const RenderResult down = render({{"downsample", n}});
        EXPECT_LT(relative_rms(canonical.image, down.image), 0.08) << "downsample " << n;
        EXPECT_NEAR(sum(down.image) / sum(canonical.image), 1.0, 0.03) << "downsample " << n;
    }
}

TEST(Igi, InterleavingStaysCloseToCanonical) {
    // Seed §4.3: VPL subsets over 3 x 3 tiles, merged by the discontinuity buffer.
    const RenderResult canonical = render({});
    const RenderResult interleaved = render({{"interleave", "3"}});
    EXPECT_LT(relative_rms(canonical.image, interleaved.image), 0.05);
    EXPECT_NEAR(sum(interleaved.image) / sum(canonical.image), 1.0, 0.03);
    // Without the filter each pixel sees one subset, 1/9 of the VPLs: far noisier.
    const RenderResult unfiltered =
        render({{"interleave", "3"}, {"depth_threshold", "0"}, {"normal_threshold", "1.0"}});
    EXPECT_GT(relative_rms(canonical.image, unfiltered.image),
              1.5 * relative_rms(canonical.image, interleaved.image));
}

TEST(Igi, AllThreeAcceleratorsTogether) {
    const RenderResult canonical = render({});
    const RenderResult fast =
        render({{"imperfect_visibility", "1"}, {"downsample", "4"}, {"interleave", "3"}}, 64, "",
               /*layers=*/true);
    EXPECT_LT(relative_rms(canonical.image, fast.image), 0.10);
    EXPECT_EQ(fast.layers.at("indirect_low").width, 16u) << "indirect at 1/4 resolution";
    // Every stage of the IGI paper's Fig. 3 is timed.
    for (const char* stage : lucent::samples::kIgiStageNames) {
        bool found = false;
        for (const auto& s : fast.stages) found |= s.name == stage;
        EXPECT_TRUE(found) << stage;
    }
}

TEST(Igi, ReflectionLayerEqualsInlineIndirectWithoutAccelerations) {
    // The gold block of cornell-materials is a mirror (Kd = 0, Ks > 0). Its reflected hits'
    // indirect light, computed inline (the paper) or as G-buffer layer 1, is the same sum.
    const RenderResult inline_indirect =
        render({{"reflection_layer", "0"}}, 64, "cornell-materials");
    const RenderResult layered =
        render({{"reflection_layer", "1"}}, 64, "cornell-materials", /*layers=*/true);
    EXPECT_LT(relative_rms(inline_indirect.image, layered.image), 1e-5);
    // The layer matters: in the pixels that see the mirror, what it adds is a visible part.
    const lucent::scene::Image& weight = layered.layers.at("reflected_weight");
    const lucent::scene::Image& irradiance = layered.layers.at("reflected_indirect");
    double through_mirror = 0, mirror_pixels = 0;
    size_t count = 0;
    for (size_t i = 0; i < weight.pixels.size(); ++i) {
        if (max_component(weight.pixels[i]) <= 0.0f) continue;
        const float3 c = weight.pixels[i] * irradiance.pixels[i] * (1.0f / 3.14159265f);
        const float3 p = layered.image.pixels[i], q = inline_indirect.image.pixels[i];
        through_mirror += c.x + c.y + c.z;
        mirror_pixels += p.x + p.y + p.z;
        EXPECT_NEAR(p.x + p.y + p.z, q.x + q.y + q.z, 1e-5 * (p.x + p.y + p.z) + 1e-7) << i;
        ++count;
    }
    EXPECT_GT(count, 50u) << "pixels that see the gold block";
    EXPECT_GT(through_mirror, 0.05 * mirror_pixels);
}

TEST(Igi, ReflectionLayerWithAcceleratorsStaysCloseToCanonical) {
    // Downsampling and interleaving now reach the mirror's reflections too.
    const RenderResult canonical = render({{"reflection_layer", "0"}}, 64, "cornell-materials");
    const RenderResult fast = render({{"imperfect_visibility", "1"},
                                      {"downsample", "4"},
                                      {"interleave", "3"},
                                      {"reflection_layer", "1"}},
                                     64, "cornell-materials");
    EXPECT_EQ(fast.report.exception_count(), 0u);
    EXPECT_LT(relative_rms(canonical.image, fast.image), 0.10);
    EXPECT_NEAR(sum(fast.image) / sum(canonical.image), 1.0, 0.05);
}

TEST(Igi, VplSlicesAddUpToTheWholeSum) {
    // The indirect pass may split a pixel's VPLs over threads (vpl_slices); the sum pass adds
    // the parts up: the same image, to rounding, for any split, with or without interleaving.
    for (const char* interleave : {"1", "3"}) {
        const RenderResult one = render({{"vpl_slices", "1"}, {"interleave", interleave}}, 32);
        for (const char* slices : {"2", "7", "0"}) {
            const RenderResult split =
                render({{"vpl_slices", slices}, {"interleave", interleave}}, 32);
            EXPECT_LT(relative_rms(one.image, split.image), 1e-5)
                << "vpl_slices " << slices << ", interleave " << interleave;
        }
    }
}

TEST(Igi, SceneWithoutLightsIsAClearError) {
    namespace fs = std::filesystem;
    const fs::path path =
        fs::temp_directory_path() / ("igi-dark-" + std::to_string(::getpid()) + ".json");
    std::ofstream(path) << R"({"camera": {"eye": [0,0,3], "look": [0,0,0]},
        "meshes": [{"positions": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,2]]}]})";
    try {
        render({}, 8, path.string());
        ADD_FAILURE() << "no error";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("has no lights"), std::string::npos) << e.what();
    }
    fs::remove(path);
}

TEST(Igi, BadOptionValuesNameTheRange) {
    try {
        render({{"downsample", "0"}}, 8);
        ADD_FAILURE() << "no error";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("downsample=0"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("[1, 16]"), std::string::npos) << e.what();
    }
}

TEST(Igi, VisibilityMapsTooLargeForMemoryAreAClearError) {
    // 4096 VPLs x 1024^2 texels would be 16 GiB of maps: refused before anything is made.
    try {
        render({{"imperfect_visibility", "3"}, {"visibility_map", "1024"}, {"vpls", "4096"}}, 8);
        ADD_FAILURE() << "no error";
    } catch (const lucent::samples::SettingsError& e) {
        EXPECT_NE(std::string(e.what()).find("visibility_map=1024"), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("16384 MiB"), std::string::npos) << e.what();
    }
}

}  // namespace

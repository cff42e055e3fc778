// Lane refill (src/cuda/device/lucent_gpu/lane_refill.cuh): on one GPU, a kernel's
// inline-trace variants let a lane whose closest-hit trace is done take its next launch index
// alone and meet the lanes of its warp still tracing. Lanes then trace different launch
// indices side by side and come back to trace() different numbers of times; whatever they
// do, every trace's closest hit must be brute force's in every launch, whichever variant and
// shape the launch-shape tuning tries, and some launch must have refilled lanes. On the CPU
// backend the same launches check the programs, and no lane is refilled.
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>

#include "tests/mesh_fixtures.h"
#include "tests/programs/lane_refill_programs.h"
#include "tests/test_support.h"

namespace {

using namespace lucent;
using namespace lucent_tests;

/// Must some launch refill lanes? On the CUDA backend, unless the environment turns the
/// variants off; through the multi-device path it depends on whether the GPUs share a tile
/// queue (which hands out whole tiles), so nothing is asked there.
bool refill_expected() {
    if (test_backend() != BackendKind::kCuda || !test_context_options().devices.empty())
        return false;
    for (const char* name : {"LUCENT_GPU_LANE_REFILL", "LUCENT_GPU_REGISTER_VARIANTS"})
        if (const char* v = std::getenv(name); v && std::strcmp(v, "off") == 0) return false;
    const char* options = std::getenv("LUCENT_NVRTC_OPTIONS");
    return !(options && (std::strstr(options, "LUCENT_GPU_MIN_BLOCKS") ||
                         std::strstr(options, "LUCENT_GPU_INLINE_TRACE")));
}

/// Two rays a launch index, how many of them it traces, and brute force's nearest hit of each.
struct RefillCase {
    std::vector<RefillRay> rays;
    std::vector<unsigned> trace_count;
    std::vector<float> t;  // the nearest hit's distance, or infinity
};

/// Rays of four kinds, mixed so that a warp's traces end at very different times: straight
/// down onto the floor and clutter, steeply down, grazing the clutter (long walks), and up
/// (an early miss).
RefillCase make_case(const test_meshes::Mesh& mesh, unsigned indices, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    RefillCase c;
    for (unsigned i = 0; i < indices; ++i) {
        c.trace_count.push_back(unsigned(rng() % 3));
        for (int k = 0; k < 2; ++k) {
            const float3 o = make_float3(10 * uni(rng), 10 * uni(rng), 0.3f + 1.5f * uni(rng));
            float3 d;
            switch (rng() % 4) {
                case 0:
                    d = make_float3(0, 0, -1);
                    break;
                case 1:
                    d = make_float3(uni(rng) - 0.5f, uni(rng) - 0.5f, -1.0f);
                    break;
                case 2:
                    d = make_float3(uni(rng) - 0.5f, uni(rng) - 0.5f, -0.05f);
                    break;
                default:
                    d = make_float3(uni(rng) - 0.5f, uni(rng) - 0.5f, 1.0f);
                    break;
            }
            d = normalize(d);
            c.rays.push_back({o, d, 40.0f});
            c.t.push_back(test_meshes::nearest_hit(mesh, o, d, 1e-4f, 40.0f));
        }
    }
    return c;
}

/// Launches `width` x `height` indices 48 times (the tuning's trials of every variant and
/// shape among them), checks every trace of every launch against brute force, and returns
/// whether any launch refilled lanes.
bool launch_and_check(unsigned width, unsigned height) {
    const test_meshes::Mesh mesh = test_meshes::floor_and_clutter(11, 2000);
    const RefillCase expected = make_case(mesh, width * height, width + 7 * height);
    ContextOptions options = test_context_options();
    options.register_variants = RegisterVariants::kWithKernel;  // the variants from launch 1
    Context ctx(options);
    ctx.set_entry_point_count(1);
    ctx.set_ray_type<TestPayload>(0, "radiance");
    ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(common_miss)));
    auto gen = program(ctx, LUCENT_PROGRAM(refill_cast));
    ctx.set_ray_generation_program(0, gen);
    auto material = make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1);
    (*gen)["top"] = make_geometry_group(
        ctx, {make_instance(ctx, make_triangles(ctx, mesh.positions, mesh.indices), material)});
    (*gen)["rays"] = input_buffer(ctx, expected.rays);
    (*gen)["trace_count"] = input_buffer(ctx, expected.trace_count);
    auto traced =
        ctx.create_buffer<TestPayload>(BufferType::kInputOutput, unsigned(expected.rays.size()));
    (*gen)["traced"] = traced;
    bool refilled = false;
    for (int launch = 0; launch < 48; ++launch) {
        // Mark every slot: one the program should not write must stay marked.
        std::vector<TestPayload> marked(expected.rays.size());
        for (TestPayload& p : marked) p.hit = -7;
        traced->upload(marked);
        ctx.launch(0, width, height);
        const LaunchReport& report = ctx.last_launch();
        EXPECT_EQ(report.exception_count(), 0u) << report.summary();
        if (report.lanes_refilled) {
            EXPECT_TRUE(report.trace_inlined) << "lanes are refilled by inline-trace variants";
            refilled = true;
        }
        const std::vector<TestPayload> hits = read_buffer<TestPayload>(*traced);
        size_t wrong = 0;
        for (size_t i = 0; i < hits.size() && wrong < 5; ++i) {
            const unsigned count = expected.trace_count[i / 2];
            const int want = i % 2 < count ? (std::isinf(expected.t[i]) ? 0 : 1) : -7;
            const bool right =
                hits[i].hit == want &&
                (want != 1 || std::fabs(hits[i].t - expected.t[i]) <= 1e-4f * expected.t[i]);
            if (!right) {
                ++wrong;
                ADD_FAILURE() << "launch " << launch << ", index " << i / 2 << ", trace " << i % 2
                              << " of " << count << ": hit " << hits[i].hit << " t " << hits[i].t
                              << ", expected hit " << want << " t " << expected.t[i] << " ("
                              << (report.lanes_refilled ? "lanes refilled" : "no refill") << ")";
            }
        }
    }
    return refilled;
}

/// Checks whether lanes were refilled where the answer is known.
void expect_refilled(bool refilled) {
    if (test_backend() != BackendKind::kCuda)
        EXPECT_FALSE(refilled) << "the CPU backend has no kernel variants";
    else if (refill_expected())
        EXPECT_TRUE(refilled) << "no launch ran a variant that refills lanes";
}

TEST(LaneRefill, TwoDimensionalLaunchOfPartTilesGivesBruteForcesHits) {
    // 61 x 37: tiles of 8 x 4 cut at the right and bottom edges.
    expect_refilled(launch_and_check(61, 37));
}

TEST(LaneRefill, OneDimensionalLaunchGivesBruteForcesHits) {
    expect_refilled(launch_and_check(3001, 1));
}

}  // namespace

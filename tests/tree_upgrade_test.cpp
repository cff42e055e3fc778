// Tree upgrades (ContextOptions::tree_upgrades): on the CUDA backend a Builder::kAuto group of
// triangles is built on the GPU, then its tree is replaced by the host's with spatial splits.
// Whichever tree a launch traces, its closest hits are brute force's; the upgrade happens for
// the groups and at the launch the options say, and never for a group with an any-hit program
// (which must see each triangle once) or one that refits. On the CPU backend the tree has its
// splits from the start and nothing is upgraded.
#include <chrono>
#include <cmath>
#include <random>

#include "tests/mesh_fixtures.h"
#include "tests/programs/occlusion_programs.h"
#include "tests/test_support.h"

namespace {

using namespace lucent;
using namespace lucent_tests;

const bool kOnGpu = test_backend() == BackendKind::kCuda;

/// Rays down onto the floor and its clutter, with brute force's closest hit for each.
struct RaysAndHits {
    std::vector<OcclusionQuery> queries;
    std::vector<float> t;  // the nearest hit's distance, or infinity
};

RaysAndHits rays_and_hits(const test_meshes::Mesh& mesh) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    RaysAndHits r;
    for (int i = 0; i < 500; ++i) {
        const float3 o = make_float3(10 * uni(rng), 10 * uni(rng), 2.0f);
        const float3 to = make_float3(10 * uni(rng), 10 * uni(rng), -0.5f);
        const float3 d = normalize(to - o);
        r.queries.push_back({o, d, 10.0f, 0});
        r.t.push_back(test_meshes::nearest_hit(mesh, o, d, 1e-4f, 10.0f));
    }
    return r;
}

class TreeUpgradeTest : public testing::Test {
  protected:
    /// A context with `upgrades`, and its group of the floor and clutter (Builder::kAuto).
    void start(TreeUpgrades upgrades) {
        ContextOptions options = test_context_options();
        options.tree_upgrades = upgrades;
        ctx = std::make_unique<Context>(options);
        ctx->set_entry_point_count(1);
        ctx->set_ray_type<TestPayload>(0, "radiance");
        ctx->set_miss_program(0, program(*ctx, LUCENT_PROGRAM(common_miss)));
        ctx->set_ray_generation_program(0, program(*ctx, LUCENT_PROGRAM(occlusion_cast)));
        material = make_material(*ctx, program(*ctx, LUCENT_PROGRAM(common_triangle_hit)), 1);
        instance =
            make_instance(*ctx, make_triangles(*ctx, mesh.positions, mesh.indices), material);
        group = make_geometry_group(*ctx, {instance});
        auto gen = ctx->ray_generation_program(0);
        (*gen)["top"] = group;
        (*gen)["queries"] = input_buffer(*ctx, expected.queries);
        (*gen)["occluded"] =
            ctx->create_buffer<unsigned>(BufferType::kOutput, unsigned(expected.queries.size()));
        traced =
            ctx->create_buffer<TestPayload>(BufferType::kOutput, unsigned(expected.queries.size()));
        (*gen)["traced"] = traced;
    }

    /// One launch; checks every closest hit against brute force; returns its report's count.
    unsigned launch_and_check() {
        ctx->launch(0, unsigned(expected.queries.size()));
        EXPECT_EQ(ctx->last_launch().exception_count(), 0u) << ctx->last_launch().summary();
        const std::vector<TestPayload> hits = read_buffer<TestPayload>(*traced);
        unsigned misses = 0;
        for (size_t i = 0; i < hits.size(); ++i) {
            if (std::isinf(expected.t[i])) {
                EXPECT_EQ(hits[i].hit, 0) << "ray " << i;
                ++misses;
                continue;
            }
            EXPECT_EQ(hits[i].hit, 1) << "ray " << i;
            EXPECT_NEAR(hits[i].t, expected.t[i], 1e-4f * expected.t[i]) << "ray " << i;
        }
        EXPECT_LT(misses, hits.size() / 4) << "the rays should mostly hit the floor";
        return ctx->last_launch().trees_upgraded;
    }

    const test_meshes::Mesh mesh = test_meshes::floor_and_clutter(5, 600);
    const RaysAndHits expected = rays_and_hits(mesh);
    std::unique_ptr<Context> ctx;
    std::shared_ptr<Material> material;
    std::shared_ptr<GeometryInstance> instance;
    std::shared_ptr<GeometryGroup> group;
    std::shared_ptr<Buffer> traced;
};

TEST_F(TreeUpgradeTest, WithBuildTheFirstLaunchTracesTheUpgradedTree) {
    start(TreeUpgrades::kWithBuild);
    EXPECT_EQ(launch_and_check(), kOnGpu ? 1u : 0u);
    EXPECT_EQ(launch_and_check(), 0u) << "a tree is upgraded once";
}

TEST_F(TreeUpgradeTest, InTheBackgroundALaterLaunchTracesTheUpgradedTree) {
    start(TreeUpgrades::kBackground);
    unsigned upgraded = launch_and_check();
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    for (int launch = 0; launch < (kOnGpu ? 100000 : 3) && upgraded == 0; ++launch) {
        if (std::chrono::steady_clock::now() > until) break;
        upgraded += launch_and_check();
    }
    EXPECT_EQ(upgraded, kOnGpu ? 1u : 0u);
    EXPECT_EQ(launch_and_check(), 0u) << "a tree is upgraded once";
}

TEST_F(TreeUpgradeTest, OffKeepsTheGpuTree) {
    start(TreeUpgrades::kOff);
    EXPECT_EQ(launch_and_check(), 0u);
}

TEST_F(TreeUpgradeTest, ARebuiltGroupIsUpgradedAgain) {
    start(TreeUpgrades::kWithBuild);
    EXPECT_EQ(launch_and_check(), kOnGpu ? 1u : 0u);
    // New triangles, far from every ray: a new build, and the same closest hits.
    test_meshes::Mesh more = mesh;
    const auto base = uint32_t(more.positions.size());
    more.positions.insert(
        more.positions.end(),
        {make_float3(1000, 1000, 50), make_float3(1001, 1000, 50), make_float3(1000, 1001, 50)});
    more.indices.push_back(make_uint3(base, base + 1, base + 2));
    instance->set_geometry(make_triangles(*ctx, more.positions, more.indices));
    EXPECT_EQ(launch_and_check(), kOnGpu ? 1u : 0u);
}

TEST_F(TreeUpgradeTest, AGroupWithAnAnyHitProgramKeepsItsGpuTree) {
    start(TreeUpgrades::kWithBuild);
    // Spatial splits would offer the any-hit program a triangle once per leaf it is in.
    material->set_any_hit(0, program(*ctx, LUCENT_PROGRAM(occlusion_count_all)));
    EXPECT_EQ(launch_and_check(), 0u);
}

TEST_F(TreeUpgradeTest, AGroupThatRefitsKeepsItsGpuTree) {
    start(TreeUpgrades::kWithBuild);
    // A refit moves the triangles of the tree it has: the GPU's, one slot each.
    auto refitted = ctx->create_acceleration(Builder::kAuto);
    refitted->set_refit(true);
    group->set_acceleration(refitted);
    EXPECT_EQ(launch_and_check(), 0u);
}

}  // namespace

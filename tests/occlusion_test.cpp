// lucent::occluded(): a shadow query that runs no hit programs. It must see triangles and
// custom primitives under any graph (GeometryGroup, Group, Transform), respect the ray's
// interval, and treat every primitive as opaque: any-hit programs are not run.
#include <random>

#include "lucent/device/triangle_intersect.h"
#include "tests/mesh_fixtures.h"
#include "tests/programs/occlusion_programs.h"
#include "tests/test_support.h"

namespace {

using namespace lucent;
using namespace lucent_tests;

class OcclusionTest : public testing::Test {
  protected:
    OcclusionTest() : ctx(test_context_options()) {
        ctx.set_entry_point_count(1);
        ctx.set_ray_type<TestPayload>(0, "radiance");
        ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(common_miss)));
        ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(occlusion_cast)));
    }

    /// occluded() for each query against `top`; `traced` gets trace()'s payloads.
    std::vector<unsigned> query(std::shared_ptr<Node> top, const std::vector<OcclusionQuery>& q,
                                std::vector<TestPayload>* traced = nullptr) {
        auto results = ctx.create_buffer<unsigned>(BufferType::kOutput, unsigned(q.size()));
        auto payloads = ctx.create_buffer<TestPayload>(BufferType::kOutput, unsigned(q.size()));
        auto gen = ctx.ray_generation_program(0);
        (*gen)["top"] = top;
        (*gen)["queries"] = input_buffer(ctx, q);
        (*gen)["occluded"] = results;
        (*gen)["traced"] = payloads;
        ctx.launch(0, unsigned(q.size()));
        EXPECT_EQ(ctx.last_launch().exception_count(), 0u) << ctx.last_launch().summary();
        if (traced) *traced = read_buffer<TestPayload>(*payloads);
        return read_buffer<unsigned>(*results);
    }

    Context ctx;
};

const float3 kOrigin = make_float3(0, 0, 0), kForward = make_float3(0, 0, 1);

TEST_F(OcclusionTest, TrianglesWithinTheIntervalOcclude) {
    auto square =
        make_instance(ctx, make_triangles(ctx, square_at(5.0f)),
                      make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1));
    auto top = make_geometry_group(ctx, {square});
    const auto r = query(top, {{kOrigin, kForward, 10.0f},                  // through the square
                               {kOrigin, kForward, 4.0f},                   // stops short of it
                               {kOrigin, -kForward, 10.0f},                 // away from it
                               {make_float3(20, 0, 0), kForward, 10.0f}});  // beside it
    EXPECT_EQ(r, (std::vector<unsigned>{1, 0, 0, 0}));
}

TEST_F(OcclusionTest, CustomPrimitivesUnderGroupsAndTransformsOcclude) {
    auto sphere =
        make_instance(ctx, make_spheres(ctx, {make_float4(0, 0, 5, 1)}),
                      make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 2));
    auto moved = ctx.create_transform();
    moved->set_matrix(translation(3, 0, 0));
    moved->set_child(make_geometry_group(ctx, {sphere}));
    auto top = ctx.create_group();
    top->add_child(moved);
    const auto r = query(top, {{kOrigin, normalize(make_float3(3, 0, 5)), 10.0f},  // the sphere
                               {kOrigin, kForward, 10.0f},  // where it was before the move
                               {kOrigin, normalize(make_float3(3, 0, 5)), 3.0f}});  // short
    EXPECT_EQ(r, (std::vector<unsigned>{1, 0, 0}));
}

TEST_F(OcclusionTest, LeafBoxesBlockRaysThatPassWhollyThroughThem) {
    // One tilted triangle, (0,0,4) (2,0,6) (0,2,6): the plane z = 4 + x + y over x + y <= 2,
    // and its leaf's box [0,2] x [0,2] x [4,6]. Rays along +z, at (x, y), up to tmax.
    const std::vector<float3> tilted = {make_float3(0, 0, 4), make_float3(2, 0, 6),
                                        make_float3(0, 2, 6)};
    auto triangle =
        make_instance(ctx, make_triangles(ctx, tilted),
                      make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1));
    auto group = make_geometry_group(ctx, {triangle});
    // The same triangle under a Group and an identity Transform: the traversal's frame path.
    auto transform = ctx.create_transform();
    transform->set_matrix(translation(0, 0, 0));
    transform->set_child(group);
    auto nested = ctx.create_group();
    nested->add_child(transform);
    const float3 beside = make_float3(1.9f, 1.9f, 0), through = make_float3(0.5f, 0.5f, 0);
    for (const auto& top : {std::shared_ptr<Node>(group), std::shared_ptr<Node>(nested)}) {
        const auto r = query(top, {{beside, kForward, 10.0f, 0},   // misses the triangle
                                   {beside, kForward, 10.0f, 1},   // but crosses its box
                                   {beside, kForward, 5.0f, 1},    // and ends in the box
                                   {through, kForward, 10.0f, 0},  // hits the triangle
                                   {through, kForward, 10.0f, 1},  // and crosses the box
                                   {through, kForward, 4.8f, 1},   // ends in the box
                                   {make_float3(3, 3, 0), kForward, 10.0f, 1}});  // beside both
        EXPECT_EQ(r, (std::vector<unsigned>{0, 1, 0, 1, 1, 0, 0}));
    }
}

TEST_F(OcclusionTest, AnyHitProgramsAreNotRun) {
    // An any-hit that ignores everything: trace() passes through to the miss program, the
    // occlusion query still sees the square (every primitive counts as opaque).
    auto material = make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 3);
    material->set_any_hit(0, program(ctx, LUCENT_PROGRAM(occlusion_ignore_all)));
    auto top = make_geometry_group(
        ctx, {make_instance(ctx, make_triangles(ctx, square_at(5.0f)), material)});
    std::vector<TestPayload> traced;
    const auto r = query(top, {{kOrigin, kForward, 10.0f}}, &traced);
    EXPECT_EQ(r, (std::vector<unsigned>{1}));
    EXPECT_EQ(traced[0].hit, 0) << "trace() ran the any-hit, which ignored the square";
    EXPECT_GE(traced[0].anyhit_count, 1u);
}

TEST_F(OcclusionTest, AnAnyHitProgramSeesEachTriangleOncePerRayWithEveryBuilder) {
    // Spatial splits put a triangle in several leaves; a group with an any-hit program is
    // built without them, so the program runs once per triangle a ray crosses, as brute
    // force counts them with the engine's own watertight test. The floor's box overlaps
    // everything, so kBinnedSah would split it in space, and a leaf box holding a piece of
    // the floor and some clutter lets a ray reach the whole floor triangle from another leaf.
    const test_meshes::Mesh mesh = test_meshes::floor_and_clutter(5, 600);
    std::mt19937 rng(6);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    std::vector<OcclusionQuery> queries;
    std::vector<unsigned> expected;
    const float tmin = 1e-4f;  // occlusion_cast's
    for (int i = 0; i < 400; ++i) {
        const float3 o = make_float3(10 * uni(rng), 10 * uni(rng), 2.0f);
        const float3 to = make_float3(10 * uni(rng), 10 * uni(rng), -0.5f);
        const float3 d = normalize(to - o);
        const float tmax = 10.0f;
        queries.push_back({o, d, tmax, 0});
        const WatertightRay wt = make_watertight_ray(o, d);
        unsigned crossed = 0;
        for (const uint3 tri : mesh.indices) {
            float t, b1, b2;
            crossed +=
                intersect_triangle_watertight(wt, mesh.positions[tri.x], mesh.positions[tri.y],
                                              mesh.positions[tri.z], tmin, tmax, t, b1, b2);
        }
        expected.push_back(crossed);
    }
    for (Builder builder : {Builder::kAuto, Builder::kBinnedSah, Builder::kGpuHploc}) {
        SCOPED_TRACE("builder " + std::to_string(int(builder)));
        auto material = make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 3);
        material->set_any_hit(0, program(ctx, LUCENT_PROGRAM(occlusion_ignore_all)));
        auto top = make_geometry_group(
            ctx, {make_instance(ctx, make_triangles(ctx, mesh.positions, mesh.indices), material)});
        top->set_acceleration(ctx.create_acceleration(builder));
        std::vector<TestPayload> traced;
        query(top, queries, &traced);
        unsigned crossing = 0;
        for (size_t i = 0; i < queries.size(); ++i) {
            EXPECT_EQ(traced[i].anyhit_count, expected[i]) << "ray " << i;
            crossing += expected[i] > 1;
        }
        EXPECT_GT(crossing, 10u) << "too few rays cross more than the floor";
    }
}

}  // namespace

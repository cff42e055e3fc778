// A ray type may name the graphs it traces: then only the materials below them need its
// closest hit (IGI's visibility rays trace a second graph whose materials have none).
#include <gtest/gtest.h>

#include "tests/programs/common.h"
#include "tests/test_support.h"

namespace {

using namespace lucent;
using namespace lucent_tests;

TEST(RayTypeRoots, OnlyMaterialsBelowTheRootsNeedTheClosestHit) {
    Context ctx(test_context_options());
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(common_cast)));
    // Graph A: a material with a closest hit for ray type 0. Graph B: a material without.
    auto a = make_geometry_group(
        ctx,
        {make_instance(ctx, make_triangles(ctx, square_at(1)),
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1))});
    auto bare = ctx.create_material();
    bare->set_name("boxes_only");
    auto b =
        make_geometry_group(ctx, {make_instance(ctx, make_triangles(ctx, square_at(2)), bare)});
    ctx["top"] = a;
    ctx["rays"] = ctx.create_buffer<CastRay>(BufferType::kInput, 1);
    ctx["results"] = ctx.create_buffer<TestPayload>(BufferType::kOutput, 1);

    // Ray type 1 traces graph B (so B is part of the scene); radiance names no roots.
    ctx.set_ray_type<TestPayload>(1, "visibility", /*expects_closest_hit=*/false, {b});
    ctx.set_ray_type<TestPayload>(0, "radiance");
    expect_error([&] { ctx.validate(); }, {"boxes_only", "closest-hit", "roots"}, "no roots");

    ctx.set_ray_type<TestPayload>(0, "radiance", true, {a});  // radiance traces graph A only
    EXPECT_NO_THROW(ctx.validate());
}

}  // namespace

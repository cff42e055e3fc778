// Variables (OptiX paper §3.2): the scope order each program kind
// resolves its record through, a field of every FieldKind, and changes between launches.
//
// Scope order (innermost first):
//   closest hit, any hit:                     Program, GeometryInstance, Material, Context
//   intersection, bounding box, attribute:    Program, GeometryInstance, Geometry, Context
//   ray generation, miss, exception, visit:   Program, Context
#include "tests/programs/variable_programs.h"
#include "tests/test_support.h"

namespace lucent_tests {
namespace {

class VariablesTest : public testing::Test {
  protected:
    VariablesTest() : ctx(test_context_options()) {
        ctx.set_entry_point_count(2);
        ctx.set_ray_type<VtPayload>(0, "radiance");
        miss = program(ctx, LUCENT_PROGRAM(vt_miss));
        ctx.set_miss_program(0, miss);
        caster = program(ctx, LUCENT_PROGRAM(vt_cast));
        ctx.set_ray_generation_program(0, caster);
        // Entry 1 only raises a user exception, to observe the exception program's record.
        thrower = program(ctx, LUCENT_PROGRAM(vt_throw));
        ctx.set_ray_generation_program(1, thrower);
        exception = program(ctx, LUCENT_PROGRAM(vt_exception));
        ctx.set_exception_program(1, exception);
        ctx.set_exception_enabled(kAllExceptions, true);

        closest = program(ctx, LUCENT_PROGRAM(vt_closest));
        any = program(ctx, LUCENT_PROGRAM(vt_any));
        intersect = program(ctx, LUCENT_PROGRAM(vt_sphere_intersect));
        bounds = program(ctx, LUCENT_PROGRAM(vt_sphere_bounds));
        geometry = ctx.create_geometry();
        geometry->set_primitive_count(1);
        geometry->set_intersection_program(intersect);
        geometry->set_bounding_box_program(bounds);
        (*geometry)["spheres"] = input_buffer(ctx, std::vector<float4>{make_float4(0, 0, 5, 1)});
        material = ctx.create_material();
        material->set_closest_hit(0, closest);
        material->set_any_hit(0, any);
        instance = make_instance(ctx, geometry, material);
        top = make_geometry_group(ctx, {instance});
        (*caster)["top"] = top;

        out = ctx.create_buffer<VtPayload>(BufferType::kOutput, 1);
        ctx["out"] = out;
        bb_log = ctx.create_buffer<float>(BufferType::kInputOutput, 1);
        ctx["bb_log"] = bb_log;
        ex_log = ctx.create_buffer<float>(BufferType::kInputOutput, 1);
        ctx["ex_log"] = ex_log;
        ctx["ray_direction"] = make_float3(0, 0, 1);
        // Context defaults: the outermost scope of every chain holds 4.
        for (const char* name : {"ch_value", "ah_value", "is_value", "bb_value", "attr_value",
                                 "rg_value", "miss_value", "ex_value"})
            ctx[name] = 4.0f;
        ctx["visit_value"] = 0u;
    }

    VtPayload trace_once() {
        ctx.launch(0, 1);
        return out->data<VtPayload>()[0];
    }

    /// Sets `name` = 1, 2, ... on `scopes` (innermost first), then checks that the innermost
    /// remaining one wins, removing it before the next relaunch.
    void check_scope_order(const std::string& name, const std::vector<VariableScope*>& scopes,
                           const std::function<float()>& observe) {
        for (size_t k = 0; k < scopes.size(); ++k) (*scopes[k])[name] = float(k + 1);
        for (size_t k = 0; k < scopes.size(); ++k) {
            EXPECT_EQ(observe(), float(k + 1))
                << "`" << name << "` should resolve from " << scopes[k]->scope_name();
            if (k + 1 < scopes.size()) scopes[k]->remove_variable(name);
        }
    }

    Context ctx;
    std::shared_ptr<Program> miss, caster, thrower, exception, closest, any, intersect, bounds;
    std::shared_ptr<Geometry> geometry;
    std::shared_ptr<Material> material;
    std::shared_ptr<GeometryInstance> instance;
    std::shared_ptr<GeometryGroup> top;
    std::shared_ptr<Buffer> out, bb_log, ex_log;
};

// ---- scope order per program kind ----------------------------------------------------

TEST_F(VariablesTest, ClosestHitResolvesProgramThenInstanceThenMaterialThenContext) {
    check_scope_order("ch_value", {closest.get(), instance.get(), material.get(), &ctx},
                      [&] { return trace_once().ch; });
}

TEST_F(VariablesTest, AnyHitResolvesProgramThenInstanceThenMaterialThenContext) {
    check_scope_order("ah_value", {any.get(), instance.get(), material.get(), &ctx},
                      [&] { return trace_once().ah; });
}

TEST_F(VariablesTest, IntersectionResolvesProgramThenInstanceThenGeometryThenContext) {
    check_scope_order("is_value", {intersect.get(), instance.get(), geometry.get(), &ctx},
                      [&] { return trace_once().is; });
}

TEST_F(VariablesTest, BoundingBoxResolvesProgramThenInstanceThenGeometryThenContext) {
    check_scope_order("bb_value", {bounds.get(), instance.get(), geometry.get(), &ctx}, [&] {
        // Bounding boxes are computed by the acceleration build: make sure one runs.
        top->acceleration()->mark_dirty();
        bb_log->upload(std::vector<float>{-1.0f});
        trace_once();
        return bb_log->data<float>()[0];
    });
}

TEST_F(VariablesTest, AttributeProgramResolvesProgramThenInstanceThenGeometryThenContext) {
    auto triangles = make_triangles(ctx, square_at(3));
    auto attributes = program(ctx, LUCENT_PROGRAM(vt_triangle_attributes));
    triangles->set_attribute_program(attributes);
    auto triangle_instance = make_instance(ctx, triangles, material);
    (*caster)["top"] = make_geometry_group(ctx, {triangle_instance});
    check_scope_order("attr_value",
                      {attributes.get(), triangle_instance.get(), triangles.get(), &ctx},
                      [&] { return trace_once().attr; });
}

TEST_F(VariablesTest, RayGenerationResolvesProgramThenContext) {
    check_scope_order("rg_value", {caster.get(), &ctx}, [&] { return trace_once().rg; });
}

TEST_F(VariablesTest, MissResolvesProgramThenContext) {
    ctx["ray_direction"] = make_float3(0, 0, -1);  // away from the sphere
    check_scope_order("miss_value", {miss.get(), &ctx}, [&] {
        const VtPayload p = trace_once();
        EXPECT_EQ(p.hit, 0);
        return p.miss;
    });
}

TEST_F(VariablesTest, ExceptionResolvesProgramThenContext) {
    check_scope_order("ex_value", {exception.get(), &ctx}, [&] {
        ex_log->upload(std::vector<float>{-1.0f});
        ctx.launch(1, 1);
        return ex_log->data<float>()[0];
    });
}

TEST_F(VariablesTest, VisitResolvesProgramThenContext) {
    // Two children that differ only in their instance's ch_value (10 and 20).
    auto visit = program(ctx, LUCENT_PROGRAM(vt_visit));
    auto selector = ctx.create_selector();
    selector->set_visit_program(visit);
    for (float value : {10.0f, 20.0f}) {
        auto child_instance = make_instance(ctx, geometry, material);
        (*child_instance)["ch_value"] = value;
        selector->add_child(make_geometry_group(ctx, {child_instance}));
    }
    (*caster)["top"] = selector;
    (*visit)["visit_value"] = 1u;
    ctx["visit_value"] = 0u;
    EXPECT_EQ(trace_once().ch, 20.0f) << "the program's visit_value (1) wins";
    visit->remove_variable("visit_value");
    EXPECT_EQ(trace_once().ch, 10.0f) << "then the context's (0)";
}

// ---- scopes outside a program kind's chain are not searched ----------------------------

TEST_F(VariablesTest, ClosestHitDoesNotSeeGeometryVariables) {
    ctx.remove_variable("ch_value");
    (*geometry)["ch_value"] = 1.0f;
    expect_error([&] { ctx.validate(); }, {"ch_value"}, "validate");
}

TEST_F(VariablesTest, IntersectionDoesNotSeeMaterialVariables) {
    ctx.remove_variable("is_value");
    (*material)["is_value"] = 1.0f;
    expect_error([&] { ctx.validate(); }, {"is_value"}, "validate");
}

TEST_F(VariablesTest, RayGenerationDoesNotSeeInstanceVariables) {
    ctx.remove_variable("rg_value");
    (*instance)["rg_value"] = 1.0f;
    expect_error([&] { ctx.validate(); }, {"rg_value"}, "validate");
}

// ---- records are per instance, not per shared object ------------------------------------

TEST_F(VariablesTest, SharedGeometryGetsEachInstancesIntersectionVariable) {
    // One Geometry in two instances placed left and right; each instance sets is_value.
    auto left = make_instance(ctx, geometry, material);
    auto right = make_instance(ctx, geometry, material);
    (*left)["is_value"] = 1.0f;
    (*right)["is_value"] = 2.0f;
    auto root = ctx.create_group();
    for (auto [instance, x] : {std::pair{left, -3.0f}, std::pair{right, 3.0f}}) {
        auto t = ctx.create_transform();
        t->set_matrix(translation(x, 0, 0));
        t->set_child(make_geometry_group(ctx, {instance}));
        root->add_child(t);
    }
    (*caster)["top"] = root;
    ctx["ray_direction"] = make_float3(-3, 0, 5);
    EXPECT_EQ(trace_once().is, 1.0f);
    ctx["ray_direction"] = make_float3(3, 0, 5);
    EXPECT_EQ(trace_once().is, 2.0f);
}

TEST_F(VariablesTest, SharedProgramGetsEachMaterialsVariable) {
    // One closest-hit program object in two materials: each material's ch_value is used.
    auto other_material = ctx.create_material();
    other_material->set_closest_hit(0, closest);
    other_material->set_any_hit(0, any);
    (*material)["ch_value"] = 10.0f;
    (*other_material)["ch_value"] = 20.0f;
    // A second sphere behind the origin, with the fixture's (is_value-reading) programs.
    auto behind = ctx.create_geometry();
    behind->set_primitive_count(1);
    behind->set_intersection_program(intersect);
    behind->set_bounding_box_program(bounds);
    (*behind)["spheres"] = input_buffer(ctx, std::vector<float4>{make_float4(0, 0, -5, 1)});
    top->add_child(make_instance(ctx, behind, other_material));
    EXPECT_EQ(trace_once().ch, 10.0f);
    ctx["ray_direction"] = make_float3(0, 0, -1);
    EXPECT_EQ(trace_once().ch, 20.0f);
}

TEST_F(VariablesTest, CallableResolvesItsVariablesOnItselfThenTheContext) {
    // The callable field of AllKinds; every other field is set on the context.
    auto gen = program(ctx, LUCENT_PROGRAM(vt_all_kinds));
    ctx.set_ray_generation_program(0, gen);
    ctx["f"] = 0.0f;
    ctx["f2"] = make_float2(0, 0);
    ctx["f3"] = make_float3(0, 0, 0);
    ctx["f4"] = make_float4(0, 0, 0, 0);
    ctx["i"] = 0;
    ctx["i2"] = make_int2(0, 0);
    ctx["i3"] = make_int3(0, 0, 0);
    ctx["i4"] = make_int4(0, 0, 0, 0);
    ctx["u"] = 0u;
    ctx["u2"] = make_uint2(0, 0);
    ctx["u3"] = make_uint3(0, 0, 0);
    ctx["u4"] = make_uint4(0, 0, 0, 0);
    ctx["m"] = translation(0, 0, 0);
    ctx["values"] = input_buffer(ctx, std::vector<float>{1});
    auto texels = ctx.create_buffer<float4>(BufferType::kInput, 1, 1);
    texels->upload(std::vector<float4>{make_float4(0, 0, 0, 0)});
    auto sampler = ctx.create_texture_sampler();
    sampler->set_buffer(texels);
    ctx["tex"] = sampler;
    ctx["scene"] = top;
    ctx["light"].set_user(Light{});
    auto all_out = ctx.create_buffer<AllKindsOut>(BufferType::kOutput, 1);
    ctx["all_out"] = all_out;
    // A callable with a variable: the Context's value is found when the callable has none.
    auto scale = program(ctx, LUCENT_PROGRAM(vt_scale));
    ctx["fn"] = scale;
    ctx["scale"] = 3.0f;
    ctx.launch(0, 1);
    EXPECT_EQ(all_out->data<AllKindsOut>()[0].called.z, 9.0f);
    (*scale)["scale"] = 5.0f;
    ctx.launch(0, 1);
    EXPECT_EQ(all_out->data<AllKindsOut>()[0].called.z, 15.0f);
}

TEST_F(VariablesTest, RetypedVariableIsRejectedAndAcceptedAgainWhenFixed) {
    EXPECT_EQ(trace_once().rg, 4.0f);
    ctx["rg_value"] = make_float3(1, 2, 3);
    expect_error([&] { trace_once(); }, {"rg_value", "float3"}, "float3 for a float field");
    ctx["rg_value"] = 6.0f;
    EXPECT_EQ(trace_once().rg, 6.0f);
}

// ---- changes between launches -----------------------------------------------------------

TEST_F(VariablesTest, ChangedVariableTakesEffectAtTheNextLaunch) {
    EXPECT_EQ(trace_once().rg, 4.0f);
    ctx["rg_value"] = 7.0f;
    EXPECT_EQ(trace_once().rg, 7.0f);
    (*material)["ch_value"] = 8.0f;
    EXPECT_EQ(trace_once().ch, 8.0f);
    (*geometry)["spheres"] = input_buffer(ctx, std::vector<float4>{make_float4(0, 0, -5, 1)});
    top->acceleration()->mark_dirty();
    EXPECT_EQ(trace_once().hit, 0) << "the sphere was rebound behind the ray";
}

// ---- a field of every FieldKind -----------------------------------------------------------

TEST_F(VariablesTest, EveryFieldKindReachesTheRecord) {
    auto gen = program(ctx, LUCENT_PROGRAM(vt_all_kinds));
    ctx.set_ray_generation_program(0, gen);
    VariableScope& s = *gen;
    s["f"] = 1.5f;
    s["f2"] = make_float2(1, 2);
    s["f3"] = make_float3(3, 4, 5);
    s["f4"] = make_float4(6, 7, 8, 9);
    s["i"] = -1;
    s["i2"] = make_int2(-2, 2);
    s["i3"] = make_int3(-3, 3, 30);
    s["i4"] = make_int4(-4, 4, 40, 400);
    s["u"] = 5u;
    s["u2"] = make_uint2(6, 60);
    s["u3"] = make_uint3(7, 70, 700);
    s["u4"] = make_uint4(8, 80, 800, 8000);
    const Matrix4x3 m{{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}};
    s["m"] = m;
    auto values = input_buffer(ctx, std::vector<float>{1, 2, 3, 4.5f});
    s["values"] = values;
    auto texels = ctx.create_buffer<float4>(BufferType::kInput, 1, 1);
    texels->upload(std::vector<float4>{make_float4(0.25f, 0.5f, 0.75f, 1)});
    auto sampler = ctx.create_texture_sampler();
    sampler->set_buffer(texels);
    s["tex"] = sampler;
    s["scene"] = top;
    s["fn"] = program(ctx, LUCENT_PROGRAM(vt_negate));
    s["light"].set_user(Light{make_float3(1, 2, 3), 42.0f, 0xabcu});
    auto all_out = ctx.create_buffer<AllKindsOut>(BufferType::kOutput, 1);
    s["all_out"] = all_out;
    ctx.launch(0, 1);

    const AllKindsOut o = all_out->data<AllKindsOut>()[0];
    EXPECT_EQ(o.f, 1.5f);
    EXPECT_EQ(o.f2.x, 1.0f);
    EXPECT_EQ(o.f2.y, 2.0f);
    EXPECT_EQ(o.f3.x, 3.0f);
    EXPECT_EQ(o.f3.z, 5.0f);
    EXPECT_EQ(o.f4.x, 6.0f);
    EXPECT_EQ(o.f4.w, 9.0f);
    EXPECT_EQ(o.i, -1);
    EXPECT_EQ(o.i2.x, -2);
    EXPECT_EQ(o.i2.y, 2);
    EXPECT_EQ(o.i3.z, 30);
    EXPECT_EQ(o.i4.w, 400);
    EXPECT_EQ(o.u, 5u);
    EXPECT_EQ(o.u2.y, 60u);
    EXPECT_EQ(o.u3.z, 700u);
    EXPECT_EQ(o.u4.w, 8000u);
    for (int k = 0; k < 12; ++k) EXPECT_EQ(o.m.m[k], m.m[k]) << "matrix element " << k;
    EXPECT_EQ(o.value_count, 4u);
    EXPECT_EQ(o.value_sum, 10.5f);
    EXPECT_EQ(o.texel.x, 0.25f);
    EXPECT_EQ(o.texel.y, 0.5f);
    EXPECT_EQ(o.texel.z, 0.75f);
    EXPECT_EQ(o.handle_hit, 1) << "a trace against the Handle field hits the sphere";
    EXPECT_EQ(o.called.x, -1.0f);
    EXPECT_EQ(o.called.y, -2.0f);
    EXPECT_EQ(o.called.z, -3.0f);
    EXPECT_EQ(o.light.position.y, 2.0f);
    EXPECT_EQ(o.light.intensity, 42.0f);
    EXPECT_EQ(o.light.flags, 0xabcu);

    // New buffer contents and a rebound buffer are both seen at the next launch. New
    // contents are only uploaded; new texels rebuild the texture, through a recompile.
    values->upload(std::vector<float>{10, 20, 30, 40});
    ctx.launch(0, 1);
    EXPECT_EQ(all_out->data<AllKindsOut>()[0].value_sum, 100.0f);
    EXPECT_FALSE(ctx.last_launch().recompiled) << "new buffer contents need no recompile";
    texels->upload(std::vector<float4>{make_float4(0.5f, 0.25f, 0.125f, 1)});
    ctx.launch(0, 1);
    EXPECT_EQ(all_out->data<AllKindsOut>()[0].texel.x, 0.5f);
    EXPECT_EQ(all_out->data<AllKindsOut>()[0].texel.z, 0.125f);
    EXPECT_TRUE(ctx.last_launch().recompiled) << "a texture is rebuilt from new texels";
    s["values"] = input_buffer(ctx, std::vector<float>{1, 1});
    ctx.launch(0, 1);
    EXPECT_EQ(all_out->data<AllKindsOut>()[0].value_count, 2u);
    EXPECT_EQ(all_out->data<AllKindsOut>()[0].value_sum, 2.0f);
}

TEST_F(VariablesTest, VariableValueReportsItsKind) {
    ctx["a_float3"] = make_float3(1, 2, 3);
    const VariableValue* value = ctx.find_variable("a_float3");
    ASSERT_NE(value, nullptr);
    EXPECT_EQ(value->kind, FieldKind::kFloat3);
    EXPECT_EQ(ctx.find_variable("never_set"), nullptr);
    ctx.remove_variable("a_float3");
    EXPECT_EQ(ctx.find_variable("a_float3"), nullptr);
}

}  // namespace
}  // namespace lucent_tests

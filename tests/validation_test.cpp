// Validation (docs/architecture.md, "Scene compile"): every wrong scene is rejected by validate() and by
// launch() with a lucent::Error that names the object and says what to do; wrong API
// calls throw at the call. Words are matched case-insensitively.
#include <limits>

#include "tests/programs/validation_programs.h"
#include "tests/test_support.h"

namespace lucent_tests {
namespace {

using testing::HasSubstr;

constexpr unsigned kRays = 4;

class ValidationTest : public CasterFixture {
  protected:
    /// Binds the caster's variables so that only the defect under test is left.
    template <class N>
    void bind_caster(std::shared_ptr<N> top) {
        (*caster)["top"] = top;
        (*caster)["rays"] = input_buffer(
            ctx, std::vector<CastRay>(kRays,
                                      cast_ray(make_float3(0.3f, 0.1f, 0), make_float3(0, 0, 1))));
        (*caster)["results"] = ctx.create_buffer<TestPayload>(BufferType::kOutput, kRays);
    }

    /// A geometry group: one square at z = 2 with `material`.
    std::shared_ptr<GeometryGroup> square_with(std::shared_ptr<Material> material) {
        return make_geometry_group(
            ctx, {make_instance(ctx, make_triangles(ctx, square_at(2)), material)});
    }

    /// validate() and launch() must both throw an Error mentioning every word.
    std::string expect_rejected(std::initializer_list<std::string> words) {
        expect_error([&] { ctx.validate(); }, words, "validate()");
        return expect_error([&] { ctx.launch(0, kRays); }, words, "launch()");
    }
};

// ---- a valid scene first: the negative tests below differ from it in one defect --------

TEST_F(ValidationTest, ValidSceneValidatesAndLaunches) {
    bind_caster(
        square_with(make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1)));
    EXPECT_NO_THROW(ctx.validate());
    EXPECT_NO_THROW(ctx.launch(0, kRays));
}

// ---- programs ----------------------------------------------------------------------

TEST(ValidationStandaloneTest, UnboundRayGenerationProgramIsRejected) {
    Context ctx(test_context_options());
    ctx.set_entry_point_count(1);
    const std::string message =
        expect_error([&] { ctx.validate(); }, {"ray generation"}, "validate()");
    EXPECT_TRUE(mentions_any(message, {"entry", "set_ray_generation_program"})) << message;
    expect_error([&] { ctx.launch(0, 4); }, {"ray generation"}, "launch()");
}

TEST_F(ValidationTest, MaterialWithoutClosestHitForAReachingRayTypeIsRejected) {
    auto material = ctx.create_material();
    material->set_name("glass");
    bind_caster(square_with(material));
    const std::string message = expect_rejected({"glass", "closest"});
    EXPECT_TRUE(mentions_any(message, {"radiance", "ray type 0"})) << message;
    EXPECT_TRUE(mentions_any(message, {"set_closest_hit", "expects_closest_hit"}))
        << "the message should say how to fix it: " << message;
}

TEST_F(ValidationTest, RayTypeThatDoesNotExpectClosestHitAcceptsAnyHitOnlyMaterial) {
    // Visibility rays work through any-hit and miss (RayTypeDesc::expects_closest_hit false).
    ctx.set_ray_type<TestPayload>(0, "visibility", /*expects_closest_hit=*/false);
    auto material = ctx.create_material();
    material->set_any_hit(0, program(ctx, LUCENT_PROGRAM(vat_anyhit_count)));
    bind_caster(square_with(material));
    EXPECT_NO_THROW(ctx.validate());
    EXPECT_NO_THROW(ctx.launch(0, kRays));
}

TEST_F(ValidationTest, MissProgramWithAnotherPayloadTypeIsRejected) {
    ctx.set_miss_program(0, program(ctx, LUCENT_PROGRAM(vat_miss_other)));
    bind_caster(
        square_with(make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1)));
    const std::string message = expect_rejected({"vat_miss_other", "payload"});
    EXPECT_TRUE(mentions_any(message, {"OtherPayload"})) << message;
    EXPECT_TRUE(mentions_any(message, {"TestPayload", "radiance"})) << message;
}

TEST_F(ValidationTest, ClosestHitWithAnotherPayloadTypeIsRejected) {
    auto material = ctx.create_material();
    material->set_closest_hit(0, program(ctx, LUCENT_PROGRAM(vat_closest_other)));
    bind_caster(square_with(material));
    const std::string message = expect_rejected({"vat_closest_other", "payload"});
    EXPECT_TRUE(mentions_any(message, {"OtherPayload"})) << message;
}

TEST_F(ValidationTest, ClosestHitAttributesDifferentFromTheIntersectionsAreRejected) {
    // Sphere intersection writes SphereAttributes; this closest hit reads TriangleAttributes.
    bind_caster(make_geometry_group(
        ctx,
        {make_instance(ctx, make_spheres(ctx, {make_float4(0, 0, 5, 1)}),
                       make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1))}));
    const std::string message = expect_rejected({"attribute"});
    EXPECT_TRUE(mentions_any(message, {"common_triangle_hit", "common_sphere_intersect"}))
        << message;
}

TEST_F(ValidationTest, ClosestHitAttributesDifferentFromBuiltInTrianglesAreRejected) {
    // Triangles without an attribute program give TriangleAttributes.
    bind_caster(
        square_with(make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 1)));
    const std::string message = expect_rejected({"attribute", "common_sphere_hit"});
    EXPECT_TRUE(mentions_any(message, {"TriangleAttributes"})) << message;
}

// ---- variables ------------------------------------------------------------------------

TEST_F(ValidationTest, VariableOfTheWrongTypeIsRejected) {
    auto material = ctx.create_material();
    material->set_name("plaster");
    material->set_closest_hit(0, program(ctx, LUCENT_PROGRAM(vat_shade)));
    (*material)["kd"] = 0.5f;  // the field is a float3
    bind_caster(square_with(material));
    const std::string message = expect_rejected({"kd", "float3"});
    EXPECT_TRUE(mentions_any(message, {"plaster", "vat_shade"})) << message;
}

TEST_F(ValidationTest, UnresolvedVariableIsRejected) {
    auto material = ctx.create_material();
    material->set_closest_hit(0, program(ctx, LUCENT_PROGRAM(vat_shade)));
    bind_caster(square_with(material));
    expect_rejected({"kd", "vat_shade"});
}

TEST_F(ValidationTest, FixingTheVariableMakesTheSceneValid) {
    auto material = ctx.create_material();
    material->set_closest_hit(0, program(ctx, LUCENT_PROGRAM(vat_shade)));
    (*material)["kd"] = 0.5f;
    bind_caster(square_with(material));
    EXPECT_THROW(ctx.validate(), Error);
    (*material)["kd"] = make_float3(0.5f, 0.5f, 0.5f);
    EXPECT_NO_THROW(ctx.validate());
    EXPECT_NO_THROW(ctx.launch(0, kRays));
}

TEST_F(ValidationTest, BufferWithAnotherElementTypeIsRejected) {
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(vat_write_image)));
    auto image = ctx.create_buffer<float3>(BufferType::kOutput, 4, 4);
    image->set_name("rgb_frame");
    ctx["image"] = image;  // the field is BufferView<float>
    expect_error([&] { ctx.validate(); }, {"image", "float3"}, "validate()");
    expect_error([&] { ctx.launch(0, 4, 4); }, {"image", "float3"}, "launch()");
}

TEST_F(ValidationTest, ObjectOfTheWrongKindForAFieldIsRejected) {
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(vat_write_image)));
    ctx["image"] = ctx.create_texture_sampler();  // a texture where a buffer is read
    expect_error([&] { ctx.validate(); }, {"image"}, "texture for a buffer field");
    ctx["image"] = ctx.create_group();  // a node where a buffer is read
    expect_error([&] { ctx.validate(); }, {"image"}, "node for a buffer field");
    ctx["image"] = 1.0f;
    expect_error([&] { ctx.validate(); }, {"image"}, "float for a buffer field");
}

TEST_F(ValidationTest, CallableOfAnotherSignatureIsRejected) {
    auto gen = program(ctx, LUCENT_PROGRAM(vat_call_float));
    ctx.set_ray_generation_program(0, gen);
    (*gen)["fn"] = program(ctx, LUCENT_PROGRAM(vat_callable_float3));
    const std::string message = expect_error([&] { ctx.validate(); }, {"fn"}, "validate()");
    EXPECT_TRUE(mentions_any(message, {"signature", "float3"})) << message;
    (*gen)["fn"] = program(ctx, LUCENT_PROGRAM(vat_callable_float));
    EXPECT_NO_THROW(ctx.validate());
    // A program that is not a callable at all.
    (*gen)["fn"] = program(ctx, LUCENT_PROGRAM(common_miss));
    expect_error([&] { ctx.validate(); }, {"fn"}, "a miss program as a callable");
}

TEST_F(ValidationTest, IncompleteNodesAreRejectedWithWhatToSet) {
    {
        auto geometry = ctx.create_geometry();
        geometry->set_name("no_programs");
        geometry->set_primitive_count(1);
        bind_caster(make_geometry_group(
            ctx, {make_instance(
                     ctx, geometry,
                     make_material(ctx, program(ctx, LUCENT_PROGRAM(common_sphere_hit)), 1))}));
        expect_rejected({"no_programs"});
    }
    {
        auto selector = ctx.create_selector();
        selector->set_name("no_visit");
        bind_caster(selector);
        expect_rejected({"no_visit", "visit"});
    }
    {
        auto transform = ctx.create_transform();
        transform->set_name("no_child");
        bind_caster(transform);
        expect_rejected({"no_child", "child"});
    }
    {
        auto instance = ctx.create_geometry_instance();
        instance->set_name("no_material");
        instance->set_geometry(make_triangles(ctx, square_at(2)));
        bind_caster(make_geometry_group(ctx, {instance}));
        expect_rejected({"no_material", "material"});
    }
    {
        auto instance = ctx.create_geometry_instance();
        instance->set_name("no_geometry");
        instance->add_material(
            make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1));
        bind_caster(make_geometry_group(ctx, {instance}));
        expect_rejected({"no_geometry", "geometry"});
    }
}

TEST_F(ValidationTest, MalformedTriangleBuffersAreRejected) {
    auto material = make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1);
    {
        auto triangles = make_triangles(ctx, {make_float3(0, 0, 0), make_float3(1, 0, 0)});
        triangles->set_name("two_vertices");
        bind_caster(make_geometry_group(ctx, {make_instance(ctx, triangles, material)}));
        expect_rejected({"two_vertices"});
    }
    {
        auto triangles =
            make_triangles(ctx, {make_float3(0, 0, 0), make_float3(1, 0, 0), make_float3(0, 1, 0)},
                           {make_uint3(0, 1, 7)});
        triangles->set_name("bad_index");
        bind_caster(make_geometry_group(ctx, {make_instance(ctx, triangles, material)}));
        expect_rejected({"bad_index", "7"});
    }
    {
        auto triangles = make_triangles(ctx, square_at(2));
        triangles->set_name("bad_material_index");
        triangles->set_material_indices(input_buffer(ctx, std::vector<unsigned>{0, 2}));
        bind_caster(make_geometry_group(ctx, {make_instance(ctx, triangles, material)}));
        expect_rejected({"bad_material_index", "material"});
    }
}

TEST_F(ValidationTest, TheFirstBadIndexOfALongBufferIsNamed) {
    // 40 triangles: the compile checks indices 16 at a time, then a tail (120 = 7 * 16 + 8
    // vertex indices; 40 = 2 * 16 + 8 material indices); a bad one in a step or in the
    // tail, and the first of two, is the one the message names.
    auto material = make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1);
    std::vector<float3> vertices;
    std::vector<uint3> indices;
    for (unsigned i = 0; i < 40; ++i) {
        const float x = float(i);
        vertices.insert(vertices.end(), {make_float3(x, 0, 2), make_float3(x + 1, 0, 2),
                                         make_float3(x, 1, 2)});
        indices.push_back(make_uint3(3 * i, 3 * i + 1, 3 * i + 2));
    }
    for (const auto& [first, second] : {std::pair{20u, 38u}, std::pair{38u, 39u}}) {
        std::vector<uint3> bad = indices;
        bad[first].y = 500 + first;
        bad[second].z = 900;
        auto triangles = make_triangles(ctx, vertices, bad);
        triangles->set_name("long_index_buffer");
        bind_caster(make_geometry_group(ctx, {make_instance(ctx, triangles, material)}));
        expect_rejected({"long_index_buffer", "triangle " + std::to_string(first),
                         "vertex " + std::to_string(500 + first)});
    }
    for (const unsigned at : {7u, 33u}) {
        std::vector<unsigned> material_indices(40, 0);
        material_indices[at] = 3;
        material_indices[39] = 4;
        auto triangles = make_triangles(ctx, vertices, indices);
        triangles->set_name("long_material_indices");
        triangles->set_material_indices(input_buffer(ctx, material_indices));
        bind_caster(make_geometry_group(ctx, {make_instance(ctx, triangles, material)}));
        expect_rejected({"long_material_indices", "triangle " + std::to_string(at),
                         "selects material 3"});
    }
    // The same buffers without the bad indices compile.
    bind_caster(make_geometry_group(
        ctx, {make_instance(ctx, make_triangles(ctx, vertices, indices), material)}));
    EXPECT_NO_THROW(ctx.validate());
}

TEST_F(ValidationTest, ProgramOfTheWrongKindIsRejectedAtTheCall) {
    auto miss = program(ctx, LUCENT_PROGRAM(common_miss));
    auto material = ctx.create_material();
    expect_error([&] { material->set_closest_hit(0, miss); }, {"closest"}, "miss as closest hit");
    expect_error([&] { material->set_any_hit(0, miss); }, {"any"}, "miss as any hit");
    expect_error([&] { ctx.set_ray_generation_program(0, miss); }, {"ray generation"},
                 "miss as ray generation");
    expect_error([&] { ctx.set_miss_program(0, caster); }, {"miss"}, "ray generation as miss");
    auto geometry = ctx.create_geometry();
    expect_error(
        [&] {
            geometry->set_intersection_program(program(ctx, LUCENT_PROGRAM(common_sphere_bounds)));
        },
        {"intersection"}, "bounding box as intersection");
    expect_error(
        [&] {
            geometry->set_bounding_box_program(
                program(ctx, LUCENT_PROGRAM(common_sphere_intersect)));
        },
        {"bounding"}, "intersection as bounding box");
}

TEST_F(ValidationTest, AfterAFailedLaunchFixingTheSceneLaunchesAgain) {
    // A failed compile must not leave a broken compiled scene behind.
    auto material = ctx.create_material();
    material->set_closest_hit(0, program(ctx, LUCENT_PROGRAM(vat_shade)));
    bind_caster(square_with(material));
    (*material)["kd"] = make_float3(1, 2, 3);
    EXPECT_NO_THROW(ctx.launch(0, kRays));
    (*material)["kd"] = 1.0f;
    EXPECT_THROW(ctx.launch(0, kRays), Error);
    EXPECT_THROW(ctx.launch(0, kRays), Error) << "the failure is not forgotten by a relaunch";
    (*material)["kd"] = make_float3(4, 5, 6);
    auto results = ctx.create_buffer<TestPayload>(BufferType::kOutput, kRays);
    (*caster)["results"] = results;
    ASSERT_NO_THROW(ctx.launch(0, kRays));
    EXPECT_EQ(results->data<TestPayload>()[0].point.y, 5.0f);
}

// ---- graph ----------------------------------------------------------------------------

TEST_F(ValidationTest, CycleInTheGraphIsRejected) {
    auto group = ctx.create_group();
    group->set_name("loop_group");
    auto transform = ctx.create_transform();
    transform->set_name("loop_transform");
    transform->set_matrix(translation(1, 0, 0));
    transform->set_child(group);
    bool rejected_early = false;
    try {
        group->add_child(transform);  // rejecting the cycle right here is also fine
    } catch (const Error& e) {
        rejected_early = true;
        EXPECT_THAT(lowercase(e.what()), HasSubstr("cycle"));
    }
    if (!rejected_early) {
        bind_caster(group);
        const std::string message = expect_rejected({"cycle"});
        EXPECT_TRUE(mentions_any(message, {"loop_group", "loop_transform"})) << message;
        group->remove_child(0);  // break the cycle so the objects can be freed
    }
}

TEST_F(ValidationTest, NonFiniteTransformIsRejected) {
    auto transform = ctx.create_transform();
    transform->set_name("broken_transform");
    transform->set_child(
        square_with(make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1)));
    Matrix4x3 m = translation(0, 0, 0);
    m.m[5] = std::numeric_limits<float>::quiet_NaN();
    try {
        transform->set_matrix(m);  // rejecting NaN right here is also fine
    } catch (const Error& e) {
        EXPECT_THAT(lowercase(e.what()), HasSubstr("broken_transform"));
        return;
    }
    bind_caster(transform);
    const std::string message = expect_rejected({"broken_transform"});
    EXPECT_TRUE(mentions_any(message, {"nan", "finite"})) << message;
}

// ---- launch sizes and buffers ---------------------------------------------------------

TEST_F(ValidationTest, ZeroLaunchSizeIsRejected) {
    bind_caster(
        square_with(make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1)));
    for (auto launch : std::vector<std::function<void()>>{
             [&] { ctx.launch(0, 0); }, [&] { ctx.launch(0, 4, 0); }, [&] { ctx.launch(0, 0, 4); },
             [&] { ctx.launch(0, 4, 4, 0); }}) {
        const std::string message = expect_error(launch, {"launch"}, "zero-size launch");
        EXPECT_TRUE(mentions_any(message, {"size", "zero", "empty"})) << message;
    }
}

TEST_F(ValidationTest, OutputBufferOfAnotherSizeThanTheLaunchIsRejected) {
    ctx.set_ray_generation_program(0, program(ctx, LUCENT_PROGRAM(vat_write_image)));
    auto image = ctx.create_buffer<float>(BufferType::kOutput, 4, 4);
    image->set_name("frame");
    ctx["image"] = image;
    const std::string message = expect_error([&] { ctx.launch(0, 8, 8); }, {"frame"}, "launch 8x8");
    EXPECT_TRUE(mentions_any(message, {"size", "4x4", "8x8", "resize"})) << message;
    // The matching size launches.
    EXPECT_NO_THROW(ctx.launch(0, 4, 4));
}

// ---- wrong API calls -----------------------------------------------------------------------

TEST_F(ValidationTest, EntryPointIndexOutOfRangeIsRejected) {
    bind_caster(
        square_with(make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1)));
    expect_error([&] { ctx.launch(1, kRays); }, {"entry"}, "launch(1)");
    expect_error([&] { ctx.set_ray_generation_program(3, caster); }, {"entry"},
                 "set_ray_generation_program(3)");
    expect_error([&] { ctx.set_exception_program(3, caster); }, {"entry"},
                 "set_exception_program(3)");
}

TEST_F(ValidationTest, RayTypeIndexOutOfRangeIsRejected) {
    auto miss = program(ctx, LUCENT_PROGRAM(common_miss));
    expect_error([&] { ctx.set_miss_program(3, miss); }, {"ray type"}, "set_miss_program(3)");
    expect_error([&] { ctx.ray_type(3); }, {"ray type"}, "ray_type(3)");
    // Ray types are numbered without gaps: declaring 5 while only 0 exists leaves 1..4
    // undeclared. Rejecting it at the call or at validate() are both fine.
    try {
        ctx.set_ray_type<TestPayload>(5, "far");
    } catch (const Error& e) {
        EXPECT_THAT(lowercase(e.what()), HasSubstr("ray type"));
        return;
    }
    bind_caster(
        square_with(make_material(ctx, program(ctx, LUCENT_PROGRAM(common_triangle_hit)), 1)));
    expect_error([&] { ctx.validate(); }, {"ray type"},
                 "validate() with ray types 1..4 undeclared");
}

TEST_F(ValidationTest, MapWithAnotherElementTypeIsRejected) {
    auto buffer = ctx.create_buffer<float>(BufferType::kInput, 8);
    buffer->set_name("weights");
    expect_error([&] { buffer->map<int>(); }, {"weights", "float", "int"}, "map<int>");
    EXPECT_NO_THROW(buffer->map<float>());
    buffer->unmap();
    expect_error([&] { buffer->data<float3>(); }, {"weights", "float3"}, "data<float3>");
    expect_error([&] { buffer->upload(std::vector<float>(3, 1.0f)); }, {"weights"},
                 "upload of 3 into 8");
}

// An empty buffer takes an empty vector (samples::bind_lights uploads no point lights this
// way): both pointers are null, which memcpy must not be given even for no bytes (UBSan's
// "null pointer passed as argument 2" once, caught by scripts/test-sanitized.sh).
TEST_F(ValidationTest, EmptyUploadIntoAnEmptyBufferCopiesNothing) {
    auto lights = ctx.create_buffer<float4>(BufferType::kInput, 0);
    EXPECT_NO_THROW(lights->upload(std::vector<float4>{}));
    EXPECT_EQ(lights->count(), 0u);
    lights->resize(2);
    lights->upload(std::vector<float4>{make_float4(1, 2, 3, 4), make_float4(5, 6, 7, 8)});
    EXPECT_EQ(lights->data<float4>()[1].z, 7.0f);
}

TEST_F(ValidationTest, UnknownProgramNameIsRejectedWithTheContextsModulesOrHowToAddOne) {
    Context fresh;
    std::string message = expect_error([&] { fresh.create_program("vat_shade"); },
                                       {"vat_shade"}, "create_program before add_module");
    EXPECT_TRUE(mentions_any(message, {"add_module"})) << message;
    fresh.add_module("test_validation");
    message = expect_error([&] { fresh.create_program("no_such_program"); },
                           {"no_such_program", "test_validation"}, "create_program");
    // A program of an added module works by its name.
    EXPECT_EQ(fresh.create_program("vat_shade")->kind(), ProgramKind::kClosestHit);
}

}  // namespace
}  // namespace lucent_tests

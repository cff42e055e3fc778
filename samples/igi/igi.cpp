// Host setup of the IGI sample: the scene as triangles with per-triangle materials, point
// lights, a VPL buffer filled by its own entry point, then the camera entry point.
#include "samples/igi/igi.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "samples/igi/igi_programs.h"
#include "samples/scene_setup.h"
#include "samples/settings_error.h"
#include "scene/scene.h"

namespace lucent::samples {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

RenderResult render_igi(const RenderSettings& settings) {
    const SampleInfo& info = igi_sample_info();
    check_options(settings, info);
    const int paths = get_int_option(settings, info, "vpls", 1, 65536);
    const int bounces = get_int_option(settings, info, "bounces", 1, 8);
    const float min_d_fraction = get_float_option(settings, info, "min_d", 0.0f, 10.0f);
    const int max_depth = get_int_option(settings, info, "max_depth", 1, 16);
    const int imperfect = get_int_option(settings, info, "imperfect_visibility", 0, 1);
    const Clock::time_point setup_start = Clock::now();
    const scene::Scene input =
        scene::load_scene(settings.scene.empty() ? "cornell-point" : settings.scene);
    if (input.point_lights.empty())
        throw SettingsError("igi: scene '" + input.name +
                            "' has no point lights; IGI traces its particles from point lights "
                            "(try --scene cornell-point, or add a point light in a JSON scene)");

    RenderResult out;
    Context ctx(settings.context_options());
    out.backend = ctx.backend_name();
    out.backend_notice = ctx.backend_notice();
    ctx.set_ray_type<igi::RadiancePayload>(igi::kRadianceRay, "radiance");
    ctx.set_ray_type<igi::ShadowPayload>(igi::kShadowRay, "shadow", /*expects_closest_hit=*/false);
    ctx.set_ray_type<igi::ParticlePayload>(igi::kParticleRay, "particle");
    ctx.set_ray_type<igi::ShadowPayload>(igi::kVplShadowRay, "vpl shadow",
                                         /*expects_closest_hit=*/false);
    ctx.set_max_recursion_depth(unsigned(max_depth) + 1);

    const float extent = scene_extent(input);
    ctx["scene_epsilon"] = std::max(1e-4f, 1e-4f * extent);
    ctx["min_d"] = min_d_fraction * extent;
    ctx["max_depth"] = unsigned(max_depth);
    ctx["bounces"] = unsigned(bounces);

    std::vector<igi::PointLight> lights;
    for (const auto& l : input.point_lights) lights.push_back({l.position, l.intensity});
    auto light_buffer =
        ctx.create_buffer<igi::PointLight>(BufferType::kInput, unsigned(lights.size()));
    light_buffer->upload(lights);
    ctx["lights"] = light_buffer;
    auto vpls = ctx.create_buffer<igi::Vpl>(BufferType::kInputOutput, unsigned(paths * bounces));
    ctx["vpls"] = vpls;

    auto surface = ctx.create_program(LUCENT_PROGRAM(igi_surface));
    auto particle = ctx.create_program(LUCENT_PROGRAM(igi_particle_hit));
    auto blocked = ctx.create_program(LUCENT_PROGRAM(igi_shadow_blocked));
    std::vector<std::shared_ptr<Material>> materials;
    for (const auto& m : input.materials) {
        auto material = ctx.create_material();
        material->set_name(m.name);
        material->set_closest_hit(igi::kRadianceRay, surface);
        material->set_closest_hit(igi::kParticleRay, particle);
        material->set_any_hit(igi::kShadowRay, blocked);
        (*material)["Kd"] = m.diffuse;
        (*material)["Ks"] = m.specular;
        (*material)["Ke"] = m.emission;
        materials.push_back(material);
    }
    auto attributes = ctx.create_program(LUCENT_PROGRAM(igi_attributes));
    auto top = ctx.create_geometry_group();
    // Imperfect visibility (seed §4.1): a second graph, one box per triangle as custom
    // primitives, traced only by VPL shadow rays.
    auto boxes = ctx.create_geometry_group();
    auto box_bounds = ctx.create_program(LUCENT_PROGRAM(igi_triangle_box_bounds));
    auto box_intersect = ctx.create_program(LUCENT_PROGRAM(igi_triangle_box_intersect));
    auto box_material = ctx.create_material();
    box_material->set_name("box");
    box_material->set_any_hit(igi::kVplShadowRay, blocked);
    for (const auto& mesh : input.meshes) {
        const MeshBuffers buffers = upload_mesh(ctx, mesh);
        const auto& vertices = buffers.positions;
        const auto& indices = buffers.triangles;
        auto triangles = ctx.create_geometry_triangles();
        triangles->set_vertices(vertices);
        triangles->set_indices(indices);
        triangles->set_material_indices(buffers.materials);
        triangles->set_attribute_program(attributes);
        (*triangles)["positions"] = vertices;
        (*triangles)["triangles"] = indices;
        auto instance = ctx.create_geometry_instance();
        instance->set_geometry(triangles);
        for (const auto& material : materials) instance->add_material(material);
        top->add_child(instance);

        auto box_geometry = ctx.create_geometry();
        box_geometry->set_primitive_count(unsigned(mesh.indices.size()));
        box_geometry->set_bounding_box_program(box_bounds);
        box_geometry->set_intersection_program(box_intersect);
        (*box_geometry)["positions"] = vertices;
        (*box_geometry)["triangles"] = indices;
        auto box_instance = ctx.create_geometry_instance();
        box_instance->set_geometry(box_geometry);
        box_instance->add_material(box_material);
        boxes->add_child(box_instance);
    }
    ctx["top_object"] = top;
    ctx["vpl_shadow_object"] = boxes;
    ctx["imperfect_visibility"] = unsigned(imperfect);
    // Radiance and particle rays trace the scene; the boxes need none of their programs.
    ctx.set_ray_type<igi::RadiancePayload>(igi::kRadianceRay, "radiance", true, {top});
    ctx.set_ray_type<igi::ParticlePayload>(igi::kParticleRay, "particle", true, {top});

    const PinholeFrame frame =
        pinhole_frame(input.camera, float(settings.width) / float(settings.height));
    auto output = ctx.create_buffer<float4>(BufferType::kOutput, settings.width, settings.height);
    auto camera = ctx.create_program(LUCENT_PROGRAM(igi_camera));
    (*camera)["eye"] = input.camera.eye;
    (*camera)["W"] = frame.W;
    (*camera)["U"] = frame.U;
    (*camera)["V"] = frame.V;
    (*camera)["output"] = output;
    ctx.set_entry_point_count(2);
    ctx.set_ray_generation_program(0, camera);
    ctx.set_ray_generation_program(1, ctx.create_program(LUCENT_PROGRAM(igi_generate_vpls)));
    ctx.set_miss_program(igi::kRadianceRay, ctx.create_program(LUCENT_PROGRAM(igi_miss)));
    out.stages.push_back(
        {"scene setup", ms_since(setup_start),
         input.name + ", " + std::to_string(input.triangle_count()) + " triangles"});

    // VPL generation: one launch, one thread per light path (seed §4).
    ctx.launch(1, unsigned(paths));
    const LaunchReport generation = ctx.last_launch();
    if (generation.jit_ms > 0)
        out.stages.push_back(
            {"megakernel JIT", generation.jit_ms,
             generation.jit_cached ? "loaded from the kernel cache" : "cold NVRTC compile"});
    out.stages.push_back(
        {"VPL generation", generation.launch_ms,
         std::to_string(paths) + " paths x " + std::to_string(bounces) + " bounces"});
    timed_launch(ctx, 0, settings, out);
    out.stages.back().name = "direct + specular + indirect";
    // The scene was compiled by the VPL launch: report it under compile, not generation.
    for (StageTiming& stage : out.stages)
        if (stage.name == "compile + accel")
            stage.ms += generation.compile_ms + generation.accel_ms;
    out.report.jit_ms = std::max(out.report.jit_ms, generation.jit_ms);
    out.report.jit_cached = out.report.jit_cached || generation.jit_cached;
    out.image = image_from_output(*output);
    return out;
}

}  // namespace

const SampleInfo& igi_sample_info() {
    static const SampleInfo info{
        "igi",
        "Instant Global Illumination (Marques and Santos, seed §4), canonical form: VPLs from the "
        "point lights along Halton paths, direct light, specular reflections and Eq. (1)",
        {
            {"vpls", "180", "light paths traced from the point lights (1..65536)"},
            {"bounces", "1", "VPLs per path: diffuse bounces recorded (1..8)"},
            {"min_d", "0.1",
             "Eq. (1)'s bounding distance, as a fraction of the scene's size (0..10)"},
            {"max_depth", "4", "deepest specular reflection tree (1..16)"},
            {"imperfect_visibility", "0",
             "1: VPL shadow rays against the triangles' bounding boxes (seed §4.1), 0: exact"},
        },
        render_igi,
    };
    return info;
}

}  // namespace lucent::samples

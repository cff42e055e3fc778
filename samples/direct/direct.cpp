// Host setup of the direct-lighting sample: one GeometryTriangles per mesh with its material
// indices, one Material per scene material, lights in buffers, and a pinhole camera.
#include "samples/direct/direct.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include "samples/direct/direct_programs.h"
#include "samples/scene_setup.h"
#include "samples/settings_error.h"
#include "scene/scene.h"

namespace lucent::samples {

namespace {

using Clock = std::chrono::steady_clock;

RenderResult render_direct(const RenderSettings& settings) {
    const SampleInfo& info = direct_sample_info();
    check_options(settings, info);
    const int area_samples = get_int_option(settings, info, "area_samples", 1, 1024);
    const float ambient = get_float_option(settings, info, "ambient", 0.0f, 1.0f);
    const Clock::time_point setup_start = Clock::now();
    const scene::Scene input =
        scene::load_scene(settings.scene.empty() ? "cornell" : settings.scene);

    RenderResult out;
    Context ctx(settings.context_options());
    out.backend = ctx.backend_name();
    out.backend_notice = ctx.backend_notice();
    ctx.set_ray_type<direct::RadiancePayload>(direct::kRadianceRay, "radiance");
    ctx.set_ray_type<direct::ShadowPayload>(direct::kShadowRay, "shadow",
                                            /*expects_closest_hit=*/false);
    ctx.set_max_recursion_depth(2);  // camera ray, then shadow rays

    // Lights; an emitter with no light source of its own still shows its emission.
    bind_lights<direct::PointLight, direct::AreaLight>(ctx, input);
    ctx["area_samples"] = unsigned(area_samples);
    ctx["scene_epsilon"] = std::max(1e-4f, 1e-4f * scene_extent(input));

    DiffuseTextures texture_for(ctx);
    auto lambert = ctx.create_program(LUCENT_PROGRAM(direct::direct_lambert));
    std::vector<std::shared_ptr<Material>> materials;
    for (const auto& m : input.materials) {
        auto material = ctx.create_material();
        material->set_name(m.name);
        material->set_closest_hit(direct::kRadianceRay, lambert);
        (*material)["Kd"] = m.diffuse + make_float3(ambient);
        (*material)["Ke"] = m.emission;
        (*material)["diffuse_map"] = texture_for(m.diffuse_texture);
        materials.push_back(material);
    }
    auto attributes = ctx.create_program(LUCENT_PROGRAM(direct::direct_attributes));
    auto top = mesh_group(ctx, input, attributes, materials);
    ctx["top_object"] = top;

    const PinholeFrame frame =
        pinhole_frame(input.camera, float(settings.width) / float(settings.height));
    auto output = ctx.create_buffer<float4>(BufferType::kOutput, settings.width, settings.height);
    auto camera = ctx.create_program(LUCENT_PROGRAM(direct::direct_camera));
    (*camera)["eye"] = input.camera.eye;
    (*camera)["W"] = frame.W;
    (*camera)["U"] = frame.U;
    (*camera)["V"] = frame.V;
    (*camera)["output"] = output;
    ctx.set_ray_generation_program(0, camera);
    auto miss = ctx.create_program(LUCENT_PROGRAM(direct::direct_miss));
    (*miss)["background"] = make_float3(0.0f);
    ctx.set_miss_program(direct::kRadianceRay, miss);
    out.stages.push_back(
        {"scene setup",
         std::chrono::duration<double, std::milli>(Clock::now() - setup_start).count(),
         input.name + ", " + std::to_string(input.triangle_count()) + " triangles"});

    timed_launch(ctx, 0, settings, out);
    out.image = image_from_output(*output);
    return out;
}

}  // namespace

const SampleInfo& direct_sample_info() {
    static const SampleInfo info{
        "direct",
        "Direct lighting of any scene (--scene cornell, cornell-point, FILE.obj or FILE.json): "
        "Lambertian surfaces, emission, point and area lights with shadow rays",
        {
            {"area_samples", "16",
             "shadow rays per area light per pixel, a stratified grid (1..1024)"},
            {"ambient", "0", "added to every diffuse reflectance, to see unlit parts (0..1)"},
        },
        render_direct,
    };
    return info;
}

}  // namespace lucent::samples

// The direct-lighting sample: any scene (built-in, OBJ or JSON) with Lambertian surfaces,
// emission, point lights and area lights with shadow rays (programs in direct_programs.h).
// One GeometryTriangles per mesh with its material indices, one Material per scene material,
// the lights in buffers, and the pinhole camera in a buffer.
#include <algorithm>
#include <memory>
#include <vector>

#include "samples/aov_passes.h"
#include "samples/camera_session.h"
#include "samples/direct/direct_programs.h"
#include "samples/scene_setup.h"
#include "samples/stages.h"
#include "scene/scene.h"

namespace lucent::samples {
namespace {

/// What build() made: the output buffer and the scene's own camera.
struct DirectScene {
    std::shared_ptr<Buffer> output;
    scene::Camera camera;
    std::string note;  // "cornell, 32 triangles"
};

/// Builds the scene of settings.scene (default: cornell) into `ctx`, its camera program at
/// entry 0 reading `camera`.
DirectScene build(Context& ctx, const RenderSettings& settings, const OptionValues& options,
                  const CameraBuffer& camera, AovPasses* aovs = nullptr) {
    const float ambient = options.number("ambient");
    const scene::Scene input = load_render_scene(settings);
    ctx.set_ray_type<direct::RadiancePayload>(direct::kRadianceRay, "radiance");
    ctx.set_ray_type<direct::ShadowPayload>(direct::kShadowRay, "shadow",
                                            /*expects_closest_hit=*/false);
    ctx.set_max_recursion_depth(2);  // camera ray, then shadow rays

    // Lights: the scene's point and area lights and its emissive triangles; without any, a
    // headlight at the eye that lights a white surface facing the camera at the scene
    // camera's distance d to radiance 1 (intensity pi d^2).
    bind_lights(ctx, input);
    const float d = length(input.camera.look - input.camera.eye);
    ctx["headlight"] = report_if_unlit(input, "direct", "lighting it with a headlight at the eye")
                           ? make_float3(0.0f)
                           : make_float3(3.14159265f * d * d);
    ctx["camera"] = camera.buffer();
    ctx["area_samples"] = unsigned(options.integer("area_samples"));
    ctx["scene_size"] = scene_size(input);

    DiffuseTextures texture_for(ctx, &input);
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
    if (aovs) aovs->add_to(materials);
    auto attributes = ctx.create_program(LUCENT_PROGRAM(sample_common::mesh_normal_uv));
    ctx["top_object"] = mesh_group(ctx, input, attributes, materials);

    DirectScene out{ctx.create_buffer<float4>(BufferType::kOutput, settings.width, settings.height),
                    input.camera,
                    scene_note(input)};
    auto program = ctx.create_program(LUCENT_PROGRAM(direct::direct_camera));
    (*program)["camera"] = camera.buffer();
    (*program)["output"] = out.output;
    ctx.set_ray_generation_program(0, program);
    auto miss = ctx.create_program(LUCENT_PROGRAM(direct::direct_miss));
    (*miss)["background"] = make_float3(0.0f);
    ctx.set_miss_program(direct::kRadianceRay, miss);
    return out;
}

/// `lucent view`: the scene built once; every option is a material or context variable
/// baked at build time, so an option change rebuilds it (cheap next to a frame).
class DirectSession final : public CameraSession {
  public:
    DirectSession(const Sample& sample, const RenderSettings& settings, const OptionValues& options)
        : CameraSession(sample, settings) {
        const DirectScene scene = build(context(), settings, options, camera());
        set_output(scene.output);
        start_at(scene.camera, pinhole_camera(scene.camera, settings.aspect()));
    }
};

class DirectSample final : public Sample {
  public:
    DirectSample()
        : Sample("direct",
                 "Direct lighting of any scene (--scene cornell, cornell-point, FILE.obj or "
                 "FILE.json): Lambertian surfaces, emission, point and area lights with shadow rays",
                 {
                     SampleOption::integer("area_samples", 16, 1, 1024,
                                           "shadow rays per area light per pixel, a stratified grid"),
                     SampleOption::number("ambient", 0.0f, 0.0f, 1.0f,
                                          "added to every diffuse reflectance, to see unlit parts"),
                 }) {}

    RenderResult render(const RenderSettings& settings) const override {
        const OptionValues options = read_options(settings);
        const Clock::time_point setup_start = Clock::now();
        Context ctx(settings.context_options());
        RenderResult out = result_for(ctx);
        CameraBuffer camera(ctx);
        // The G-buffer's ray type and entry points come after the sample's own.
        AovPasses aovs(ctx, settings, direct::kShadowRay + 1, 1, camera.buffer());
        const DirectScene scene = build(ctx, settings, options, camera, &aovs);
        aovs.set_colour(scene.output);
        const sample_common::PinholeCamera pinhole = pinhole_camera(scene.camera, settings.aspect());
        camera.set(pinhole);
        out.camera = scene.camera;
        out.stages.push_back({"scene setup", ms_since(setup_start), scene.note});
        timed_launch(ctx, 0, settings, out);
        out.image = image_from_output(*scene.output);
        aovs.finish(pinhole, out);
        return out;
    }

    bool writes_aovs() const override { return true; }

    std::unique_ptr<InteractiveSession> open(const RenderSettings& settings) const override {
        return std::make_unique<DirectSession>(*this, settings, read_options(settings));
    }
};

const RegisterSample<DirectSample> kRegistered(/*help_order=*/20);

}  // namespace
}  // namespace lucent::samples

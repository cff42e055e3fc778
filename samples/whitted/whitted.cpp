// Host setup of the Whitted sample (OptiX paper §6.1, Fig. 7), after the OptiX SDK's
// "whitted": one GeometryGroup with a parallelogram floor, a metal sphere and a thin-shell
// glass sphere, three materials, point lights, and two ray types (radiance, shadow).
#include "samples/whitted/whitted.h"

#include <cmath>
#include <numbers>
#include <vector>

#include "lucent.h"
#include "samples/camera_session.h"
#include "samples/scene_setup.h"
#include "samples/settings_error.h"
#include "samples/stages.h"
#include "samples/whitted/whitted_programs.h"

namespace lucent::samples {
namespace {

constexpr const char* kSceneName = "whitted";

/// The sample's own pinhole camera: W from the eye to the look-at point (not of unit length),
/// U and V from the image centre to its right and top edges.
sample_common::PinholeCamera camera_frame(const WhittedLayout& layout, float aspect) {
    float3 W = layout.lookat - layout.eye;
    float distance = length(W);
    float3 U = normalize(cross(W, layout.up));
    float3 V = normalize(cross(U, W));
    float half_height =
        distance * std::tan(0.5f * layout.vfov_degrees * std::numbers::pi_v<float> / 180.0f);
    return {layout.eye, U * (half_height * aspect), V * half_height, W};
}

/// The sample's camera as a scene::Camera, with the parts settings.camera gives replaced.
scene::Camera whitted_camera(const WhittedLayout& layout, const RenderSettings& settings) {
    scene::Camera own;
    own.eye = layout.eye;
    own.look = layout.lookat;
    own.up = layout.up;
    own.fov_degrees = layout.vfov_degrees;
    return settings.camera.empty() ? own : settings.camera.applied_to(own);
}

/// The pinhole of the render: the sample's own frame, or that of the camera asked for.
sample_common::PinholeCamera whitted_pinhole(const WhittedLayout& layout,
                                             const RenderSettings& settings) {
    if (settings.camera.empty()) return camera_frame(layout, settings.aspect());
    return pinhole_camera(whitted_camera(layout, settings), settings.aspect());
}

/// The sample's --set options, checked.
struct WhittedOptions {
    int antialiasing = 0;
    float aa_threshold = 0.1f;
    int max_depth = 6;
    int shadows = 1;
    int lights = 1;
    int motion = 0;

    explicit WhittedOptions(const OptionValues& v)
        : antialiasing(v.on("aa")),
          aa_threshold(v.number("aa_threshold")),
          max_depth(v.integer("max_depth")),
          shadows(v.on("shadows")),
          lights(v.integer("lights")),
          motion(v.on("motion")) {}
};

/// Up to three white point lights; their colours share one unit of intensity so the
/// exposure stays the same whatever the count.
std::vector<whitted::BasicLight> make_lights(const WhittedLayout& layout, int count) {
    const float3 positions[3] = {layout.key_light, layout.fill_lights[0], layout.fill_lights[1]};
    std::vector<whitted::BasicLight> lights;
    for (int i = 0; i < count; ++i) {
        whitted::BasicLight light{};
        light.position = positions[i];
        light.color = make_float3(layout.light_intensity / float(count));
        light.casts_shadow = 1;
        lights.push_back(light);
    }
    return lights;
}

/// The scene's size and name checked; SettingsError on bad input.
void check_scene(const RenderSettings& settings) {
    if (!settings.scene.empty() && settings.scene != kSceneName)
        throw SettingsError("--scene " + settings.scene +
                            ": the whitted sample has one built-in scene; accepted names are "
                            "'whitted' (or no --scene)");
    if (settings.scene_camera)
        throw SettingsError("--camera " + std::to_string(*settings.scene_camera) +
                            ": scene 'whitted' has 0 cameras of its own (use --eye --look "
                            "--up --fov)");
    if (settings.width == 0 || settings.height == 0)
        throw SettingsError("whitted: image size " + std::to_string(settings.width) + "x" +
                            std::to_string(settings.height) + " is empty; give --size WxH");
}

/// The options that are variables: changed in place by the session.
void set_variables(Context& ctx, Program& camera, const WhittedOptions& options) {
    camera["antialiasing"] = options.antialiasing;
    camera["aa_threshold"] = options.aa_threshold;
    camera["motion"] = options.motion;
    // Radiance rays nest max_depth deep below the camera's; each may cast shadow rays.
    ctx.set_max_recursion_depth(unsigned(options.max_depth) + 2);
    ctx["max_depth"] = options.max_depth;
    ctx["shadows"] = options.shadows;
}

/// Ray types, exceptions, the output buffer (context variable output_buffer) of width x
/// height, and the camera (reading `camera_buffer`, entry 0), exception and miss programs.
std::shared_ptr<Buffer> create_programs(Context& ctx, const WhittedLayout& layout,
                                        const WhittedOptions& options, unsigned width,
                                        unsigned height, const CameraBuffer& camera_buffer) {
    ctx.set_ray_type<whitted::RadiancePayload>(whitted::kRadianceRay, "radiance");
    // Shadow rays need only any-hit (attenuate or stop) and no miss program: a ray that
    // reaches the light returns the attenuation the glass left it.
    ctx.set_ray_type<whitted::ShadowPayload>(whitted::kShadowRay, "shadow",
                                             /*expects_closest_hit=*/false);
    ctx.set_exception_enabled(kExceptionStackOverflow, true);
    ctx.set_exception_enabled(kExceptionBufferIndexOutOfBounds, true);

    auto output = ctx.create_buffer<float4>(BufferType::kOutput, width, height);
    output->set_name("output_buffer");
    ctx["output_buffer"] = output;

    ctx.set_entry_point_count(1);
    auto camera = ctx.create_program(LUCENT_PROGRAM(whitted::whitted_camera));
    (*camera)["camera"] = camera_buffer.buffer();
    ctx.set_ray_generation_program(0, camera);
    set_variables(ctx, *camera, options);
    auto exception = ctx.create_program(LUCENT_PROGRAM(whitted::whitted_exception));
    (*exception)["bad_color"] = make_float3(1.0f, 0.0f, 1.0f);
    ctx.set_exception_program(0, exception);

    auto miss = ctx.create_program(LUCENT_PROGRAM(whitted::whitted_miss));
    (*miss)["bg_color"] = layout.background;
    ctx.set_miss_program(whitted::kRadianceRay, miss);
    return output;
}

/// The three primitive types, each with its own programs (§6.1).
struct Shapes {
    std::shared_ptr<Geometry> floor, metal_sphere, glass_sphere;
};

Shapes create_shapes(Context& ctx, const WhittedLayout& layout) {
    auto floor = ctx.create_geometry();
    floor->set_name("floor");
    floor->set_primitive_count(1);
    floor->set_intersection_program(
        ctx.create_program(LUCENT_PROGRAM(whitted::whitted_parallelogram_intersect)));
    floor->set_bounding_box_program(
        ctx.create_program(LUCENT_PROGRAM(whitted::whitted_parallelogram_bounds)));
    {
        const float3 anchor = layout.floor_anchor;
        const float3 v1 = layout.floor_edge1, v2 = layout.floor_edge2;
        const float3 normal = normalize(cross(v1, v2));
        (*floor)["plane"] = make_float4(normal, dot(normal, anchor));
        (*floor)["v1"] = v1 / dot(v1, v1);
        (*floor)["v2"] = v2 / dot(v2, v2);
        (*floor)["anchor"] = anchor;
    }

    auto metal_sphere = ctx.create_geometry();
    metal_sphere->set_name("metal sphere");
    metal_sphere->set_primitive_count(1);
    metal_sphere->set_intersection_program(
        ctx.create_program(LUCENT_PROGRAM(whitted::whitted_sphere_intersect)));
    metal_sphere->set_bounding_box_program(
        ctx.create_program(LUCENT_PROGRAM(whitted::whitted_sphere_bounds)));

    auto glass_sphere = ctx.create_geometry();
    glass_sphere->set_name("glass sphere");
    glass_sphere->set_primitive_count(1);
    glass_sphere->set_intersection_program(
        ctx.create_program(LUCENT_PROGRAM(whitted::whitted_shell_intersect)));
    glass_sphere->set_bounding_box_program(
        ctx.create_program(LUCENT_PROGRAM(whitted::whitted_shell_bounds)));
    (*glass_sphere)["center"] = layout.glass_center;
    (*glass_sphere)["radius_outer"] = layout.glass_radius;
    (*glass_sphere)["radius_inner"] = layout.glass_radius - layout.glass_thickness;
    return {floor, metal_sphere, glass_sphere};
}

struct Materials {
    std::shared_ptr<Material> floor, metal, glass;
};

/// The checker floor, the metal and the glass, with their shadow programs.
Materials create_materials(Context& ctx, const WhittedLayout& layout) {
    auto opaque_shadow = ctx.create_program(LUCENT_PROGRAM(whitted::whitted_opaque_shadow));

    // Checker floor: the colours of Whitted's red and yellow checkers, 1 x 1 unit squares,
    // from a 2 x 2 texture with nearest filtering and repeat wrap.
    auto checker_texels = ctx.create_buffer<float4>(BufferType::kInput, 2, 2);
    checker_texels->set_name("checker texels");
    {
        const float4 red = make_float4(0.75f, 0.18f, 0.08f, 1.0f);
        const float4 yellow = make_float4(0.9f, 0.85f, 0.05f, 1.0f);
        checker_texels->upload(std::vector<float4>{red, yellow, yellow, red});
    }
    auto checker = ctx.create_texture_sampler();
    checker->set_name("checker");
    checker->set_buffer(checker_texels);
    checker->set_wrap_mode(WrapMode::kRepeat, WrapMode::kRepeat);
    checker->set_filter(FilterMode::kNearest);

    auto floor_material = ctx.create_material();
    floor_material->set_name("checker floor");
    floor_material->set_closest_hit(whitted::kRadianceRay,
                                    ctx.create_program(LUCENT_PROGRAM(whitted::whitted_checker_radiance)));
    floor_material->set_any_hit(whitted::kShadowRay, opaque_shadow);
    (*floor_material)["checker"] = checker;
    (*floor_material)["checker_scale"] = make_float2(20.0f, 20.0f);  // 40 x 40 squares
    (*floor_material)["Ks"] = make_float3(0.0f);
    (*floor_material)["phong_exp"] = 1.0f;
    (*floor_material)["reflectivity"] = make_float3(0.0f);

    auto metal_material = ctx.create_material();
    metal_material->set_name("metal");
    metal_material->set_closest_hit(whitted::kRadianceRay,
                                    ctx.create_program(LUCENT_PROGRAM(whitted::whitted_metal_radiance)));
    metal_material->set_any_hit(whitted::kShadowRay, opaque_shadow);
    (*metal_material)["Ka"] = make_float3(0.2f, 0.5f, 0.5f);
    (*metal_material)["Kd"] = make_float3(0.2f, 0.7f, 0.8f);
    (*metal_material)["Ks"] = make_float3(0.9f);
    (*metal_material)["phong_exp"] = 64.0f;
    (*metal_material)["reflectivity"] = make_float3(0.5f);

    auto glass_material = ctx.create_material();
    glass_material->set_name("glass");
    glass_material->set_closest_hit(whitted::kRadianceRay,
                                    ctx.create_program(LUCENT_PROGRAM(whitted::whitted_glass_radiance)));
    auto glass_shadow = ctx.create_program(LUCENT_PROGRAM(whitted::whitted_glass_shadow));
    // On the program's scope: the any-hit program sees it before the material's.
    (*glass_shadow)["shadow_attenuation"] = make_float3(layout.glass_shadow_transmission);
    glass_material->set_any_hit(whitted::kShadowRay, glass_shadow);
    (*glass_material)["fresnel_exponent"] = 3.0f;
    (*glass_material)["fresnel_minimum"] = 0.1f;
    (*glass_material)["fresnel_maximum"] = 1.0f;
    (*glass_material)["refraction_index"] = 1.4f;
    (*glass_material)["refraction_color"] = make_float3(1.0f);
    (*glass_material)["reflection_color"] = make_float3(1.0f);
    (*glass_material)["refraction_maxdepth"] = 10;
    (*glass_material)["reflection_maxdepth"] = 5;
    (*glass_material)["extinction_constant"] = make_float3(layout.glass_extinction);
    (*glass_material)["cutoff_color"] = make_float3(0.034f, 0.055f, 0.085f);
    (*glass_material)["importance_cutoff"] = 0.01f;
    return {floor_material, metal_material, glass_material};
}

/// One instance per shape with its material, in one GeometryGroup; with motion, the metal
/// sphere in a GeometryGroup of its own under a matrix motion Transform that moves it by
/// layout.metal_motion over the shutter [0, 1], beside the rest in a Group.
std::shared_ptr<Node> scene_group(Context& ctx, const WhittedLayout& layout, const Shapes& shapes,
                                  const Materials& materials, bool motion) {
    auto floor_instance = ctx.create_geometry_instance();
    floor_instance->set_name("floor");
    floor_instance->set_geometry(shapes.floor);
    floor_instance->add_material(materials.floor);

    auto metal_instance = ctx.create_geometry_instance();
    metal_instance->set_name("metal sphere");
    metal_instance->set_geometry(shapes.metal_sphere);
    metal_instance->add_material(materials.metal);
    // On the instance: intersection programs see GeometryInstance scope before Geometry's.
    (*metal_instance)["sphere"] = make_float4(layout.metal_center, layout.metal_radius);

    auto glass_instance = ctx.create_geometry_instance();
    glass_instance->set_name("glass sphere");
    glass_instance->set_geometry(shapes.glass_sphere);
    glass_instance->add_material(materials.glass);

    auto group = ctx.create_geometry_group();
    group->set_name("whitted scene");
    group->add_child(floor_instance);
    group->add_child(glass_instance);
    if (!motion) {
        group->add_child(metal_instance);
        return group;
    }
    auto metal_group = ctx.create_geometry_group();
    metal_group->set_name("moving metal sphere");
    metal_group->add_child(metal_instance);
    auto moving = ctx.create_transform();
    moving->set_name("metal sphere motion");
    moving->set_child(metal_group);
    const float3 d = layout.metal_motion;
    const std::vector<Matrix4x3> keys{identity_matrix(),
                                      Matrix4x3{{1, 0, 0, d.x, 0, 1, 0, d.y, 0, 0, 1, d.z}}};
    moving->set_motion_matrices(keys, MotionOptions{0.0f, 1.0f});
    auto top = ctx.create_group();
    top->set_name("whitted scene with motion");
    top->add_child(group);
    top->add_child(moving);
    return top;
}

/// Builds the whole scene of `layout` into `ctx`, the camera program reading `camera` at entry
/// 0; returns the float4 output buffer (context variable output_buffer) of width x height.
std::shared_ptr<Buffer> build_scene(Context& ctx, const WhittedLayout& layout,
                                    const WhittedOptions& options, unsigned width,
                                    unsigned height, const CameraBuffer& camera_buffer) {
    auto output = create_programs(ctx, layout, options, width, height, camera_buffer);
    const Shapes shapes = create_shapes(ctx, layout);
    auto group = scene_group(ctx, layout, shapes, create_materials(ctx, layout), options.motion);
    const std::vector<whitted::BasicLight> lights = make_lights(layout, options.lights);
    auto light_buffer =
        ctx.create_buffer<whitted::BasicLight>(BufferType::kInput, unsigned(lights.size()));
    light_buffer->set_name("lights");
    light_buffer->upload(lights);
    ctx["lights"] = light_buffer;
    ctx["top_object"] = group;
    ctx["top_shadower"] = group;
    ctx["ambient_light_color"] = make_float3(layout.ambient);
    // Secondary rays start off their surface by an offset that follows the scene's size and
    // the float spacing at the hit (samples/common/ray_offset.h); a fixed 1e-3 was a whole
    // scene at scale 1e-6 and less than a float's spacing at 1e6.
    ctx["scene_size"] = layout.size;
    return output;
}

/// `lucent view`: the scene built once; the options that are variables change in place (a
/// recompile, no rebuild); the number of lights (a buffer's size) rebuilds it.
class WhittedSession final : public CameraSession {
  public:
    WhittedSession(const Sample& sample, const RenderSettings& settings,
                   const WhittedOptions& options)
        : CameraSession(sample, settings), m_lights(options.lights), m_motion(options.motion) {
        const WhittedLayout& layout = whitted_layout();
        set_output(
            build_scene(context(), layout, options, settings.width, settings.height, camera()));
        m_camera = context().ray_generation_program(0);
        start_at(whitted_camera(layout, settings), whitted_pinhole(layout, settings));
    }

  private:
    bool apply_options(const OptionValues& values) override {
        const WhittedOptions o(values);
        if (o.lights != m_lights || o.motion != m_motion) return false;  // a new scene
        set_variables(context(), *m_camera, o);
        return true;
    }

    int m_lights;
    int m_motion;
    std::shared_ptr<Program> m_camera;
};

class WhittedSample final : public Sample {
  public:
    WhittedSample()
        : Sample(kSceneName,
                 "Whitted's sphere scene (OptiX paper §6.1, Fig. 7): checkered floor, metal and "
                 "glass-shell spheres, shadow rays, optional adaptive antialiasing",
                 {
                     SampleOption::toggle(
                         "aa", false,
                         "adaptive antialiasing: 0 = 1 ray per pixel, 1 = 4 rays, 16 where they "
                         "differ"),
                     SampleOption::number(
                         "aa_threshold", 0.1f, 0.0f, 1.0f,
                         "largest per-channel difference among the 4 rays before 16 are traced"),
                     SampleOption::integer("max_depth", 6, 1, 31,
                                           "deepest reflection/refraction ray tree"),
                     SampleOption::toggle(
                         "shadows", true,
                         "shadow rays: 0 = off, 1 = on (glass casts a lighter shadow)"),
                     SampleOption::integer("lights", 1, 1, 3,
                                           "number of point lights, sharing one intensity"),
                     SampleOption::toggle(
                         "motion", false,
                         "motion blur: the metal sphere moves during the shutter (a matrix "
                         "motion transform) and each camera ray samples a time in it"),
                 }) {}

    RenderResult render(const RenderSettings& settings) const override {
        return render_placed(settings, whitted_layout());
    }

    /// One frame of the scene of `layout`.
    RenderResult render_placed(const RenderSettings& settings, const WhittedLayout& layout) const {
        const WhittedOptions options(read_options(settings));
        check_scene(settings);
        const Clock::time_point setup_start = Clock::now();
        Context ctx(settings.context_options());
        RenderResult out = result_for(ctx);
        CameraBuffer camera(ctx);
        camera.set(whitted_pinhole(layout, settings));
        auto output = build_scene(ctx, layout, options, settings.width, settings.height, camera);
        out.stages.push_back({"scene setup", ms_since(setup_start)});
        timed_launch(ctx, 0, settings, out);
        out.image = image_from_output(*output);
        return out;
    }

    std::unique_ptr<InteractiveSession> open(const RenderSettings& settings) const override {
        const WhittedOptions options(read_options(settings));
        check_scene(settings);
        return std::make_unique<WhittedSession>(*this, settings, options);
    }
};

const RegisterSample<WhittedSample> kRegistered(/*help_order=*/10);

}  // namespace

RenderResult render_whitted(const RenderSettings& settings, const Placement& placement) {
    const auto& sample = dynamic_cast<const WhittedSample&>(find_sample(kSceneName));
    return sample.render_placed(settings, whitted_layout(placement));
}

const WhittedLayout& whitted_layout() {
    static const WhittedLayout layout = [] {
        WhittedLayout l{};
        l.eye = make_float3(11.9f, 3.6f, 1.35f);
        l.lookat = make_float3(3.3f, 1.4f, -3.8f);
        l.up = make_float3(0.0f, 1.0f, 0.0f);
        l.vfov_degrees = 34.0f;
        l.background = make_float3(0.38f, 0.5f, 0.68f);
        l.metal_center = make_float3(2.0f, 1.5f, -2.5f);
        l.metal_radius = 1.0f;
        // Up by 1.2 radii over the shutter (a bounce), clear of the glass sphere and the frame.
        l.metal_motion = make_float3(0.0f, 1.2f, 0.0f);
        l.glass_center = make_float3(4.0f, 2.3f, -4.0f);
        l.glass_radius = 1.0f;
        l.glass_thickness = 0.04f;
        l.floor_height = 0.01f;
        l.floor_anchor = make_float3(-20.0f, l.floor_height, -22.0f);
        l.floor_edge1 = make_float3(0.0f, 0.0f, 40.0f);
        l.floor_edge2 = make_float3(40.0f, 0.0f, 0.0f);
        l.key_light = make_float3(6.0f, 40.0f, 21.0f);
        l.fill_lights[0] = make_float3(-12.0f, 25.0f, 24.0f);
        l.fill_lights[1] = make_float3(30.0f, 20.0f, -30.0f);
        // With ambient 0.3 the lit floor stays below 1 (no clipped checkers).
        l.light_intensity = 0.9f;
        l.ambient = 0.3f;
        // Four surfaces (the shell's two sides, twice) let 0.85^4 = 52 % through at the
        // shadow's centre, less towards its rim where Fresnel reflection grows.
        l.glass_shadow_transmission = 0.85f;
        l.glass_extinction = std::log(0.83f);
        l.size = 40.0f;
        return l;
    }();
    return layout;
}

WhittedLayout whitted_layout(const Placement& placement) {
    WhittedLayout l = whitted_layout();
    for (float3* p : {&l.eye, &l.lookat, &l.metal_center, &l.glass_center, &l.floor_anchor,
                      &l.key_light, &l.fill_lights[0], &l.fill_lights[1]})
        *p = placement.point(*p);
    l.floor_height = l.floor_anchor.y;
    l.floor_edge1 = placement.vector(l.floor_edge1);
    l.floor_edge2 = placement.vector(l.floor_edge2);
    l.metal_motion = placement.vector(l.metal_motion);
    for (float* length : {&l.metal_radius, &l.glass_radius, &l.glass_thickness, &l.size})
        *length = placement.length(*length);
    l.glass_extinction = placement.per_length(l.glass_extinction);
    return l;
}

float2 whitted_project(float3 p, unsigned width, unsigned height) {
    const WhittedLayout& layout = whitted_layout();
    const sample_common::PinholeCamera frame = camera_frame(layout, float(width) / float(height));
    // U, V, W are orthogonal: the coordinates of p - eye in that frame, then divide by depth.
    const float3 q = p - layout.eye;
    const float depth = dot(q, frame.W) / dot(frame.W, frame.W);
    const float sx = dot(q, frame.U) / dot(frame.U, frame.U) / depth;
    const float sy = dot(q, frame.V) / dot(frame.V, frame.V) / depth;
    return make_float2(0.5f * (sx + 1.0f) * float(width), 0.5f * (1.0f - sy) * float(height));
}

}  // namespace lucent::samples

// Host setup of the instant radiosity sample (the seed blog): the scene's triangles with
// (textured) diffuse materials, its area lights, a photon launch, VPL merging on the host,
// then the G-buffer and the deferred shading pass.
#include "samples/radiosity/radiosity.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "samples/radiosity/radiosity_programs.h"
#include "samples/radiosity/vpl_grid.h"
#include "samples/scene_setup.h"
#include "samples/settings_error.h"
#include "scene/scene.h"

namespace lucent::samples {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

Bounds3 scene_bounds(const scene::Scene& scene) {
    Bounds3 b{make_float3(1e30f), make_float3(-1e30f)};
    for (const auto& mesh : scene.meshes)
        for (const float3& p : mesh.positions) {
            b.lo = fminf(b.lo, p);
            b.hi = fmaxf(b.hi, p);
        }
    return b;
}

struct Options {
    unsigned photon_side, bounces, roulette, grid, merge, gi, show_vpls, vpl_shadows, area_samples;
    float clamp;
};

Options read_options(const RenderSettings& settings, const SampleInfo& info) {
    Options o{};
    const int photons = get_int_option(settings, info, "photons", 1, 1 << 20);
    o.photon_side = unsigned(std::max(1.0, std::floor(std::sqrt(double(photons)))));
    o.bounces = unsigned(get_int_option(settings, info, "bounces", 1, 16));
    o.roulette = unsigned(get_int_option(settings, info, "roulette", 0, 1));
    o.grid = unsigned(get_int_option(settings, info, "grid", 1, 256));
    o.merge = unsigned(get_int_option(settings, info, "merge", 0, 1));
    o.gi = unsigned(get_int_option(settings, info, "gi", 0, 1));
    o.show_vpls = unsigned(get_int_option(settings, info, "show_vpls", 0, 1));
    o.vpl_shadows = unsigned(get_int_option(settings, info, "vpl_shadows", 0, 1));
    o.area_samples = unsigned(get_int_option(settings, info, "area_samples", 1, 1024));
    o.clamp = get_float_option(settings, info, "clamp", 0.0f, 10.0f);
    return o;
}

RenderResult render_radiosity(const RenderSettings& settings) {
    const SampleInfo& info = radiosity_sample_info();
    check_options(settings, info);
    const Options options = read_options(settings, info);
    const Clock::time_point setup_start = Clock::now();
    const scene::Scene input =
        scene::load_scene(settings.scene.empty() ? "cornell" : settings.scene);
    if (input.area_lights.empty())
        throw SettingsError("radiosity: scene '" + input.name +
                            "' has no area light; the photons leave area lights (try --scene "
                            "cornell, or add {\"type\": \"area\", ...} to a JSON scene's lights)");

    RenderResult out;
    Context ctx(settings.context_options());
    out.backend = ctx.backend_name();
    out.backend_notice = ctx.backend_notice();
    ctx.set_ray_type<radiosity::SurfacePayload>(radiosity::kRadianceRay, "radiance");
    ctx.set_ray_type<radiosity::ShadowPayload>(radiosity::kShadowRay, "shadow",
                                               /*expects_closest_hit=*/false);
    ctx.set_ray_type<radiosity::SurfacePayload>(radiosity::kPhotonRay, "photon");
    ctx.set_max_recursion_depth(2);

    const float extent = scene_extent(input);
    ctx["scene_epsilon"] = std::max(1e-4f, 1e-4f * extent);
    ctx["vpl_offset"] = 1e-3f * extent;
    ctx["clamp_distance"] = options.clamp * extent;
    ctx["bounces"] = options.bounces;
    ctx["roulette"] = options.roulette;
    ctx["area_samples"] = options.area_samples;
    ctx["gi"] = options.gi;
    ctx["vpl_shadows"] = options.vpl_shadows;
    ctx["show_vpls"] = options.show_vpls;
    ctx["dot_radius"] = 0.006f;

    std::vector<radiosity::AreaLight> lights;
    for (const auto& l : input.area_lights)
        lights.push_back({l.corner, l.edge1, l.edge2, l.emission});
    auto light_buffer =
        ctx.create_buffer<radiosity::AreaLight>(BufferType::kInput, unsigned(lights.size()));
    light_buffer->upload(lights);
    ctx["area_lights"] = light_buffer;
    const unsigned photons = options.photon_side * options.photon_side * unsigned(lights.size());
    auto scattered =
        ctx.create_buffer<radiosity::Vpl>(BufferType::kInputOutput, photons * options.bounces);

    DiffuseTextures texture_for(ctx);
    auto surface = ctx.create_program(LUCENT_PROGRAM(radiosity::radiosity_surface));
    std::vector<std::shared_ptr<Material>> materials;
    for (const auto& m : input.materials) {
        auto material = ctx.create_material();
        material->set_name(m.name);
        material->set_closest_hit(radiosity::kRadianceRay, surface);
        material->set_closest_hit(radiosity::kPhotonRay, surface);
        (*material)["Kd"] = m.diffuse;
        (*material)["Ke"] = m.emission;
        (*material)["diffuse_map"] = texture_for(m.diffuse_texture);
        materials.push_back(material);
    }
    auto attributes = ctx.create_program(LUCENT_PROGRAM(radiosity::radiosity_attributes));
    auto top = mesh_group(ctx, input, attributes, materials);
    ctx["top_object"] = top;

    const unsigned w = settings.width, h = settings.height;
    auto image = [&ctx, w, h] { return ctx.create_buffer<float4>(BufferType::kInputOutput, w, h); };
    ctx["gbuffer_position"] = image();
    ctx["gbuffer_normal"] = image();
    ctx["gbuffer_albedo"] = image();
    ctx["gbuffer_emission"] = image();
    auto output = ctx.create_buffer<float4>(BufferType::kOutput, w, h);
    // What shading reads: the scattered VPLs, or their merged grid (refilled below).
    auto merged = ctx.create_buffer<radiosity::Vpl>(BufferType::kInput, 1);

    auto photon_program = ctx.create_program(LUCENT_PROGRAM(radiosity::radiosity_photons));
    (*photon_program)["vpls"] = scattered;
    const PinholeFrame frame = pinhole_frame(input.camera, float(w) / float(h));
    auto gbuffer = ctx.create_program(LUCENT_PROGRAM(radiosity::radiosity_gbuffer));
    (*gbuffer)["eye"] = input.camera.eye;
    (*gbuffer)["W"] = frame.W;
    (*gbuffer)["U"] = frame.U;
    (*gbuffer)["V"] = frame.V;
    auto shade = ctx.create_program(LUCENT_PROGRAM(radiosity::radiosity_shade));
    (*shade)["eye"] = input.camera.eye;
    (*shade)["output"] = output;
    (*shade)["vpls"] = options.merge ? merged : scattered;
    ctx.set_entry_point_count(radiosity::kEntryCount);
    ctx.set_ray_generation_program(radiosity::kPhotonEntry, photon_program);
    ctx.set_ray_generation_program(radiosity::kGBufferEntry, gbuffer);
    ctx.set_ray_generation_program(radiosity::kShadeEntry, shade);
    out.stages.push_back(
        {"scene setup", ms_since(setup_start),
         input.name + ", " + std::to_string(input.triangle_count()) + " triangles"});

    // Photons: one thread each, sqrt(N) x sqrt(N) per light (the blog's launch).
    ctx.launch(radiosity::kPhotonEntry, options.photon_side, options.photon_side,
               unsigned(lights.size()));
    const LaunchReport first = ctx.last_launch();
    add_compile_stages(first, out.stages);
    out.stages.push_back({"photons", first.launch_ms,
                          std::to_string(photons) + " photons, up to " +
                              std::to_string(options.bounces) + " bounces"});

    // Merging, on the host as in the blog.
    const radiosity::Vpl* mapped = scattered->map<radiosity::Vpl>();
    const std::vector<radiosity::Vpl> raw(mapped, mapped + scattered->count());
    scattered->unmap();
    size_t live = 0;
    for (const radiosity::Vpl& v : raw) live += max_component(v.power) > 0.0f;
    if (options.merge) {
        const Clock::time_point merge_start = Clock::now();
        std::vector<radiosity::Vpl> cells = merge_vpls(raw, scene_bounds(input), options.grid);
        if (cells.empty()) cells.push_back(radiosity::Vpl{});  // no photon hit: nothing to add
        merged->resize(unsigned(cells.size()));
        merged->upload(cells);
        out.stages.push_back({"VPL merge", ms_since(merge_start),
                              std::to_string(live) + " VPLs into " + std::to_string(cells.size()) +
                                  " cells of a " + std::to_string(options.grid) + "^3 grid"});
    }

    ctx.launch(radiosity::kGBufferEntry, w, h);
    const LaunchReport gbuffer_report = ctx.last_launch();
    out.stages.push_back({"G-buffer", gbuffer_report.launch_ms, ""});
    ctx.launch(radiosity::kShadeEntry, w, h);
    out.report = ctx.last_launch();
    out.stages.push_back({"shading", out.report.launch_ms,
                          options.gi ? std::to_string(options.merge ? merged->count() : live) +
                                           " VPLs as point lights"
                                     : "direct light only"});
    out.report.jit_ms = first.jit_ms;
    out.report.jit_cached = first.jit_cached;
    out.image = image_from_output(*output);
    if (settings.keep_layers) {
        // The VPLs shading used, as a 1-row image of power (for tests), and the raw ones.
        auto vpl_image = [](const std::vector<radiosity::Vpl>& v) {
            scene::Image img;
            img.width = unsigned(v.size());
            img.height = 1;
            for (const auto& vpl : v) img.pixels.push_back(vpl.power);
            return img;
        };
        out.layers["vpl_power"] = vpl_image(raw);
        if (options.merge) {
            const radiosity::Vpl* m = merged->map<radiosity::Vpl>();
            out.layers["merged_vpl_power"] =
                vpl_image(std::vector<radiosity::Vpl>(m, m + merged->count()));
            merged->unmap();
        }
    }
    return out;
}

}  // namespace

const SampleInfo& radiosity_sample_info() {
    static const SampleInfo info{
        "radiosity",
        "Instant radiosity with deferred shading (the seed blog): photons from the area lights, "
        "a VPL at each bounce, VPLs merged into a voxel grid, then direct light plus every VPL",
        {
            {"photons", "1024",
             "photons per area light, traced from a jittered sqrt(N) x sqrt(N) grid (1..1048576)"},
            {"bounces", "3", "most VPLs a photon leaves (1..16)"},
            {"roulette", "1", "1: Russian roulette after the first bounce, 0: every bounce"},
            {"merge", "1", "1: merge the VPLs into a voxel grid (the blog's M key), 0: all"},
            {"grid", "16", "voxels along each axis of the scene's bounds for merging (1..256)"},
            {"gi", "1", "0: direct light only (the blog's I key)"},
            {"show_vpls", "0", "1: draw the VPLs as dots (the blog's L key)"},
            {"vpl_shadows", "0", "1: a shadow ray per VPL and pixel (the blog had none)"},
            {"clamp", "0.05",
             "VPL distances below this fraction of the scene's size count as it (0..10)"},
            {"area_samples", "16", "direct light: shadow rays per area light and pixel (1..1024)"},
        },
        render_radiosity,
    };
    return info;
}

}  // namespace lucent::samples

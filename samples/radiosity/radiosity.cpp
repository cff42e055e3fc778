// The instant radiosity sample (the seed blog): the scene's triangles with (textured) diffuse
// materials, its area lights, a photon launch, VPL merging on the host, then the G-buffer and
// the deferred shading pass. `lucent view` runs the same frame, the camera in a buffer.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "samples/aov_passes.h"
#include "samples/camera_session.h"
#include "samples/radiosity/radiosity_programs.h"
#include "samples/radiosity/vpl_grid.h"
#include "samples/scene_setup.h"
#include "samples/settings_error.h"
#include "samples/stages.h"
#include "scene/scene.h"

namespace lucent::samples {

namespace {

/// The scene's bounds as the VPL grid takes them.
Bounds3 grid_bounds(const scene::Scene& scene) {
    const scene::Bounds b = scene::scene_bounds(scene);
    return Bounds3{b.lo, b.hi};
}

/// The sample's --set options, checked.
struct Options {
    unsigned photon_side, bounces, roulette, grid, merge, gi, show_vpls, vpl_shadows, area_samples;
    float clamp;

    explicit Options(const OptionValues& v)
        : photon_side(unsigned(std::max(1.0, std::floor(std::sqrt(double(v.integer("photons"))))))),
          bounces(unsigned(v.integer("bounces"))),
          roulette(v.on("roulette")),
          grid(unsigned(v.integer("grid"))),
          merge(v.on("merge")),
          gi(v.on("gi")),
          show_vpls(v.on("show_vpls")),
          vpl_shadows(v.on("vpl_shadows")),
          area_samples(unsigned(v.integer("area_samples"))),
          clamp(v.number("clamp")) {}
};

/// The scene of settings.scene (default: cornell); SettingsError when it has no area light
/// (declared, or an emissive triangle).
scene::Scene load_lit_scene(const RenderSettings& settings) {
    scene::Scene input = load_render_scene(settings);
    if (area_lights(input).empty())
        throw SettingsError("radiosity: scene '" + input.name +
                            "' has no area light nor emissive triangle; the photons leave area "
                            "lights (try --scene cornell, give a material Ke in its MTL or an "
                            "emissiveFactor in its glTF file, or add {\"type\": \"area\", "
                            "...} to a JSON scene's lights)");
    return input;
}

/// Ray types and the context-wide variables.
void set_up_context(Context& ctx, const scene::Scene& input, const Options& options) {
    ctx.set_ray_type<radiosity::SurfacePayload>(radiosity::kRadianceRay, "radiance");
    ctx.set_ray_type<radiosity::ShadowPayload>(radiosity::kShadowRay, "shadow",
                                               /*expects_closest_hit=*/false);
    ctx.set_ray_type<radiosity::SurfacePayload>(radiosity::kPhotonRay, "photon");
    ctx.set_max_recursion_depth(2);

    const float size = scene_size(input);
    ctx["scene_size"] = size;
    ctx["vpl_offset"] = 1e-3f * size;
    ctx["clamp_distance"] = options.clamp * size;
    ctx["bounces"] = options.bounces;
    ctx["roulette"] = options.roulette;
    ctx["area_samples"] = options.area_samples;
    ctx["gi"] = options.gi;
    ctx["vpl_shadows"] = options.vpl_shadows;
    ctx["show_vpls"] = options.show_vpls;
    ctx["dot_radius"] = 0.006f;
}

/// One material per scene material (the same surface program for radiance and photon
/// rays), and the meshes under "top_object".
void add_geometry(Context& ctx, const scene::Scene& input, AovPasses* aovs) {
    DiffuseTextures texture_for(ctx, &input);
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
    if (aovs) aovs->add_to(materials);
    auto attributes = ctx.create_program(LUCENT_PROGRAM(sample_common::mesh_normal_uv));
    ctx["top_object"] = mesh_group(ctx, input, attributes, materials);
}

/// The buffers the passes hand each other.
struct Passes {
    unsigned lights = 0, photons = 0;
    std::shared_ptr<Buffer> scattered;  // a VPL per photon bounce
    std::shared_ptr<Buffer> merged;     // their voxel grid (refilled by merge())
    std::shared_ptr<Buffer> output;
};

/// The area lights, the G-buffer, and the three entry points: photons, G-buffer, shading.
Passes create_passes(Context& ctx, const scene::Scene& input, const Options& options,
                     unsigned w, unsigned h, const CameraBuffer& camera, AovPasses* aovs) {
    Passes p;
    const std::vector<sample_common::AreaLight> lights = area_lights(input);
    auto light_buffer =
        ctx.create_buffer<sample_common::AreaLight>(BufferType::kInput, unsigned(lights.size()));
    light_buffer->upload(lights);
    const std::vector<float> cdf = light_cdf(lights);
    auto cdf_buffer = ctx.create_buffer<float>(BufferType::kInput, unsigned(cdf.size()));
    cdf_buffer->upload(cdf);
    ctx["area_lights"] = light_buffer;
    ctx["area_light_cdf"] = cdf_buffer;
    p.lights = unsigned(lights.size());
    p.photons = options.photon_side * options.photon_side;
    p.scattered =
        ctx.create_buffer<radiosity::Vpl>(BufferType::kInputOutput, p.photons * options.bounces);

    add_geometry(ctx, input, aovs);

    auto image = [&ctx, w, h] { return ctx.create_buffer<float4>(BufferType::kInputOutput, w, h); };
    ctx["gbuffer_position"] = image();
    ctx["gbuffer_normal"] = image();
    ctx["gbuffer_albedo"] = image();
    ctx["gbuffer_emission"] = image();
    p.output = ctx.create_buffer<float4>(BufferType::kOutput, w, h);
    // What shading reads: the scattered VPLs, or their merged grid (refilled by merge()).
    p.merged = ctx.create_buffer<radiosity::Vpl>(BufferType::kInput, 1);

    auto photon_program = ctx.create_program(LUCENT_PROGRAM(radiosity::radiosity_photons));
    (*photon_program)["vpls"] = p.scattered;
    auto gbuffer = ctx.create_program(LUCENT_PROGRAM(radiosity::radiosity_gbuffer));
    (*gbuffer)["camera"] = camera.buffer();
    auto shade = ctx.create_program(LUCENT_PROGRAM(radiosity::radiosity_shade));
    (*shade)["camera"] = camera.buffer();
    (*shade)["output"] = p.output;
    (*shade)["vpls"] = options.merge ? p.merged : p.scattered;
    // At least the sample's own: the AOV passes' entry points may follow them.
    ctx.set_entry_point_count(std::max(ctx.entry_point_count(), unsigned(radiosity::kEntryCount)));
    ctx.set_ray_generation_program(radiosity::kPhotonEntry, photon_program);
    ctx.set_ray_generation_program(radiosity::kGBufferEntry, gbuffer);
    ctx.set_ray_generation_program(radiosity::kShadeEntry, shade);
    return p;
}

std::vector<radiosity::Vpl> read_vpls(Buffer& buffer) {
    const radiosity::Vpl* mapped = buffer.map<radiosity::Vpl>();
    std::vector<radiosity::Vpl> vpls(mapped, mapped + buffer.count());
    buffer.unmap();
    return vpls;
}

/// Merging, on the host as in the blog: the scattered VPLs into `passes.merged`.
void merge(const std::vector<radiosity::Vpl>& raw, size_t live, const scene::Scene& input,
           const Options& options, Passes& passes, RenderResult& out) {
    const Clock::time_point merge_start = Clock::now();
    std::vector<radiosity::Vpl> cells = merge_vpls(raw, grid_bounds(input), options.grid);
    if (cells.empty()) cells.push_back(radiosity::Vpl{});  // no photon hit: nothing to add
    passes.merged->resize(unsigned(cells.size()));
    passes.merged->upload(cells);
    out.stages.push_back({"VPL merge", ms_since(merge_start),
                          std::to_string(live) + " VPLs into " + std::to_string(cells.size()) +
                              " cells of a " + std::to_string(options.grid) + "^3 grid"});
}

/// The VPLs shading used, as 1-row images of power (for tests), and the raw ones.
void keep_vpl_layers(const std::vector<radiosity::Vpl>& raw, const Options& options,
                     Passes& passes, RenderResult& out) {
    auto vpl_image = [](const std::vector<radiosity::Vpl>& v) {
        scene::Image img;
        img.width = unsigned(v.size());
        img.height = 1;
        for (const auto& vpl : v) img.pixels.push_back(vpl.power);
        return img;
    };
    out.layers["vpl_power"] = vpl_image(raw);
    if (options.merge) out.layers["merged_vpl_power"] = vpl_image(read_vpls(*passes.merged));
}

/// The frame: photons (one thread each, sqrt(N) x sqrt(N), the blog's launch; a light each),
/// merging, the G-buffer and shading, each a stage.
void render_passes(Context& ctx, const scene::Scene& input, const Options& options,
                   const RenderSettings& settings, Passes& passes, RenderResult& out) {
    ctx.launch(radiosity::kPhotonEntry, options.photon_side, options.photon_side, 1);
    const LaunchReport first = ctx.last_launch();
    add_compile_stages(first, out.stages);
    out.stages.push_back({"photons", first.launch_ms,
                          std::to_string(passes.photons) + " photons, up to " +
                              std::to_string(options.bounces) + " bounces"});

    const std::vector<radiosity::Vpl> raw = read_vpls(*passes.scattered);
    size_t live = 0;
    for (const radiosity::Vpl& v : raw) live += max_component(v.power) > 0.0f;
    if (options.merge) merge(raw, live, input, options, passes, out);

    ctx.launch(radiosity::kGBufferEntry, settings.width, settings.height);
    out.stages.push_back({"G-buffer", ctx.last_launch().launch_ms, ""});
    ctx.launch(radiosity::kShadeEntry, settings.width, settings.height);
    out.report = ctx.last_launch();
    out.stages.push_back({"shading", out.report.launch_ms,
                          options.gi ? std::to_string(options.merge ? passes.merged->count() : live) +
                                           " VPLs as point lights"
                                     : "direct light only"});
    out.report.jit_ms = first.jit_ms;
    out.report.jit_cached = first.jit_cached;
    if (settings.keep_layers) keep_vpl_layers(raw, options, passes, out);
}

/// What a render and a session build: the scene in `ctx` and its passes, the camera
/// reading `camera`.
struct RadiosityScene {
    scene::Scene input;
    Passes passes;

    RadiosityScene(Context& ctx, const RenderSettings& settings, const Options& options,
                   const CameraBuffer& camera, AovPasses* aovs = nullptr)
        : input(load_lit_scene(settings)) {
        set_up_context(ctx, input, options);
        passes =
            create_passes(ctx, input, options, settings.width, settings.height, camera, aovs);
    }
};

/// `lucent view`: the scene built once, its frame (photons, merging, G-buffer, shading) run
/// again when the camera moves. Every option is a variable baked at build time or sizes a
/// buffer, so an option rebuilds the scene.
class RadiositySession final : public CameraSession {
  public:
    RadiositySession(const Sample& sample, const RenderSettings& settings, const Options& options)
        : CameraSession(sample, settings),
          m_options(options),
          m_scene(context(), settings, options, camera()) {
        start_at(m_scene.input.camera, pinhole_camera(m_scene.input.camera, settings.aspect()));
    }

    FrameResult frame() override {
        RenderSettings frame_settings = settings();
        frame_settings.keep_layers = false;
        RenderResult passes;
        render_passes(context(), m_scene.input, m_options, frame_settings, m_scene.passes, passes);
        return frame_of(std::move(passes), *m_scene.passes.output);
    }

  private:
    Options m_options;
    RadiosityScene m_scene;
};

class RadiositySample final : public Sample {
  public:
    RadiositySample()
        : Sample("radiosity",
                 "Instant radiosity with deferred shading (the seed blog): photons from the area "
                 "lights, a VPL at each bounce, VPLs merged into a voxel grid, then direct light "
                 "plus every VPL",
                 {
                     SampleOption::integer(
                         "photons", 1024, 1, 1 << 20,
                         "photons, traced from a jittered sqrt(N) x sqrt(N) grid of directions; each "
                         "from an area light chosen in proportion to its power"),
                     SampleOption::integer("bounces", 3, 1, 16, "most VPLs a photon leaves"),
                     SampleOption::toggle(
                         "roulette", true,
                         "1: Russian roulette after the first bounce, 0: every bounce"),
                     SampleOption::toggle(
                         "merge", true,
                         "1: merge the VPLs into a voxel grid (the blog's M key), 0: all"),
                     SampleOption::integer(
                         "grid", 16, 1, 256,
                         "voxels along each axis of the scene's bounds for merging"),
                     SampleOption::toggle("gi", true, "0: direct light only (the blog's I key)"),
                     SampleOption::toggle("show_vpls", false,
                                          "1: draw the VPLs as dots (the blog's L key)"),
                     SampleOption::toggle(
                         "vpl_shadows", false,
                         "1: a shadow ray per VPL and pixel (the blog had none)"),
                     SampleOption::number(
                         "clamp", 0.05f, 0.0f, 10.0f,
                         "VPL distances below this fraction of the scene's size count as it"),
                     SampleOption::integer("area_samples", 16, 1, 1024,
                                           "direct light: shadow rays per area light and pixel"),
                 }) {}

    RenderResult render(const RenderSettings& settings) const override {
        const Options options(read_options(settings));
        const Clock::time_point setup_start = Clock::now();
        Context ctx(settings.context_options());
        RenderResult out = result_for(ctx);
        CameraBuffer camera(ctx);
        // The G-buffer's ray type and entry points come after the sample's own.
        AovPasses aovs(ctx, settings, radiosity::kPhotonRay + 1, radiosity::kEntryCount,
                       camera.buffer());
        RadiosityScene scene(ctx, settings, options, camera, &aovs);
        aovs.set_colour(scene.passes.output);
        const sample_common::PinholeCamera pinhole =
            pinhole_camera(scene.input.camera, settings.aspect());
        camera.set(pinhole);
        out.camera = scene.input.camera;
        out.stages.push_back({"scene setup", ms_since(setup_start),
                              scene_note(scene.input)});
        render_passes(ctx, scene.input, options, settings, scene.passes, out);
        out.image = image_from_output(*scene.passes.output);
        aovs.finish(pinhole, out);
        return out;
    }

    bool writes_aovs() const override { return true; }

    std::unique_ptr<InteractiveSession> open(const RenderSettings& settings) const override {
        return std::make_unique<RadiositySession>(*this, settings, Options(read_options(settings)));
    }
};

const RegisterSample<RadiositySample> kRegistered(/*help_order=*/40);

}  // namespace
}  // namespace lucent::samples

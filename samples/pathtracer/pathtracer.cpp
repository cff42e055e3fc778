// Host setup of the path tracer: the scene's triangles with one Material per scene material
// (its closest hit chosen by MaterialKind), the area and point lights in buffers, and the
// progressive loop: one launch per sample per pixel into the accumulation buffer. `lucent
// view` runs the same camera program, one sample per pixel per frame, accumulated while the
// camera rests.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <vector>

#include "samples/aov_passes.h"
#include "samples/camera_session.h"
#include "samples/pathtracer/pathtracer_programs.h"
#include "samples/progressive_frames.h"
#include "samples/scene_setup.h"
#include "samples/stages.h"
#include "samples/view_denoiser.h"
#include "scene/scene.h"

namespace lucent::samples {

namespace {

/// A light with no emitting surface (a JSON "area" light) becomes a two-triangle emitter,
/// so that the light and BSDF strategies cover the same integral. (An emissive triangle is
/// a light already: scene::emitter_lights.)
void add_light_geometry(scene::Scene& s, float tolerance) {
    for (const scene::AreaLight& light : std::vector<scene::AreaLight>(s.area_lights)) {
        if (scene::has_emitting_geometry(s, light, tolerance)) continue;
        scene::Material m{"area light", {0, 0, 0}};
        m.emission = light.emission;
        s.materials.push_back(m);
        scene::Mesh mesh;
        mesh.name = "area light";
        mesh.positions = {light.corner, light.corner + light.edge1,
                          light.corner + light.edge1 + light.edge2, light.corner + light.edge2};
        mesh.indices = {uint3{0, 1, 2}, uint3{0, 2, 3}};
        mesh.materials.assign(2, unsigned(s.materials.size() - 1));
        scene::add_untransformed_mesh(s, std::move(mesh));
    }
}

/// The sample's --set options, checked.
struct PathOptions {
    int max_depth = 8, rr_depth = 3, nee = 1;
    float environment = 0, exposure = 1;
    int reinhard = 0, seed = 0;

    explicit PathOptions(const OptionValues& v)
        : max_depth(v.integer("max_depth")),
          rr_depth(v.integer("rr_depth")),
          nee(v.on("nee")),
          environment(v.number("environment")),
          exposure(v.number("exposure")),
          reinhard(v.on("reinhard")),
          seed(v.integer("seed")) {}
};

/// Sets the options that are variables: of the camera program and of the miss program.
void set_variables(Program& camera, Program& miss, const PathOptions& o) {
    camera["max_depth"] = unsigned(o.max_depth);
    camera["rr_depth"] = unsigned(o.rr_depth);
    camera["nee"] = unsigned(o.nee);
    camera["seed"] = unsigned(o.seed);
    camera["exposure"] = o.exposure;
    camera["reinhard"] = unsigned(o.reinhard);
    miss["environment"] = make_float3(o.environment);
}

/// What build() made that the render loop and the session need.
struct PathScene {
    scene::Camera camera;                   // the scene's own camera
    std::shared_ptr<Buffer> accum, output;  // width x height float4
    std::shared_ptr<Buffer> stream_offset;  // one unsigned: PathSession's SVGF frames
    std::shared_ptr<Program> camera_program, miss;
    std::vector<std::shared_ptr<Material>> materials;
    std::string note;                       // "cornell, 32 triangles"
};

/// The G-buffer's ray type and first entry point: after the sample's own.
constexpr unsigned kGBufferRay = 2, kGBufferEntry = 1;

/// Builds the scene of settings.scene (default: cornell) into `ctx`, the camera program at
/// entry 0 reading `camera`; each material also gets the G-buffer's hit when `aovs` is active.
PathScene build(Context& ctx, const RenderSettings& settings, const PathOptions& options,
                const CameraBuffer& camera, AovPasses* aovs = nullptr) {
    scene::Scene input = load_render_scene(settings);
    const float size = scene_size(input);
    // A light within a thousandth of the scene's size of emitting triangles has its geometry
    // (scene::emitter_lights' tolerance).
    add_light_geometry(input, 1e-3f * size);

    ctx.set_ray_type<pathtracer::PathPayload>(pathtracer::kRadianceRay, "radiance");
    ctx.set_ray_type<pathtracer::ShadowPayload>(pathtracer::kShadowRay, "shadow",
                                                /*expects_closest_hit=*/false);
    ctx.set_max_recursion_depth(2);  // the path loop's rays, then shadow rays from hits

    bind_lights(ctx, input);
    ctx["scene_size"] = size;
    report_if_unlit(input, "pathtracer", "only the environment option lights it");

    std::shared_ptr<Program> closest_hits[] = {
        ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_lambert)),
        ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_metal)),
        ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_dielectric)),
        ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_coated)),
    };
    DiffuseTextures texture_for(ctx, &input);
    std::vector<std::shared_ptr<Material>> materials;
    for (const auto& m : input.materials) {
        auto material = ctx.create_material();
        material->set_name(m.name);
        material->set_closest_hit(pathtracer::kRadianceRay, closest_hits[int(m.kind)]);
        (*material)["Kd"] = m.diffuse;
        (*material)["diffuse_map"] = texture_for(m.diffuse_texture);
        // A metal's colour is `specular`; a glTF metal carries it as its base colour in
        // `diffuse` (what the Phong samples read as Kd) and leaves `specular` black.
        const bool metal_by_diffuse =
            m.kind == scene::MaterialKind::kMetal && max_component(m.specular) <= 0.0f;
        (*material)["Ks"] = metal_by_diffuse ? m.diffuse : m.specular;
        // ... and its base colour texture, which tints that colour as it tints Kd.
        (*material)["specular_map"] = texture_for(metal_by_diffuse ? m.diffuse_texture : "");
        (*material)["Ke"] = m.emission;
        // Perceptual roughness squared (Burley 2012); a floor keeps GGX finite in float.
        (*material)["alpha"] = std::max(m.roughness * m.roughness, 1e-3f);
        (*material)["ior"] = m.ior;
        materials.push_back(material);
    }
    if (aovs) aovs->add_to(materials);
    auto attributes = ctx.create_program(LUCENT_PROGRAM(sample_common::mesh_normal_uv));
    ctx["top_object"] = mesh_group(ctx, input, attributes, materials);

    PathScene out;
    out.camera = input.camera;
    out.accum =
        ctx.create_buffer<float4>(BufferType::kInputOutput, settings.width, settings.height);
    out.output = ctx.create_buffer<float4>(BufferType::kOutput, settings.width, settings.height);
    // Each pixel's frames add up in its own element: across ranks, a rank keeps the pixels
    // it ran from frame to frame, and the image is gathered once (docs/distributed.md).
    out.accum->set_launch_index_local(true);
    out.output->set_launch_index_local(true);
    out.stream_offset = ctx.create_buffer<unsigned>(BufferType::kInput, 1);
    out.stream_offset->upload(std::vector<unsigned>{0});
    out.miss = ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_miss));
    ctx.set_miss_program(pathtracer::kRadianceRay, out.miss);
    out.camera_program = ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_camera));
    (*out.camera_program)["camera"] = camera.buffer();
    (*out.camera_program)["accum"] = out.accum;
    (*out.camera_program)["output"] = out.output;
    (*out.camera_program)["stream_offset"] = out.stream_offset;
    set_variables(*out.camera_program, *out.miss, options);
    ctx.set_ray_generation_program(0, out.camera_program);
    out.note = scene_note(input);
    out.materials = std::move(materials);
    return out;
}

/// Launches settings.spp frames (default 64) into the accumulation buffer and times them.
/// Progressive accumulation: the frame number lives in the accumulation buffer (its w), so
/// launches change nothing on the host and the compiled scene (and on the GPU the
/// megakernel) is reused; a variable per frame would recompile it every frame.
void render_frames(Context& ctx, const RenderSettings& settings, RenderResult& out) {
    render_progressive(ctx, settings, 64, out);
}

/// `lucent view`: progressive. Each frame adds one sample per pixel to the accumulation
/// buffer, whose w counts them; moving the camera or an option clears it. With SVGF on,
/// every frame renders one new sample per pixel (the accumulation restarts, the random
/// streams go on) and SVGF's history does the accumulating, across camera moves too.
class PathSession final : public CameraSession {
  public:
    PathSession(const Sample& sample, const RenderSettings& settings, const PathOptions& options)
        : CameraSession(sample, settings) {
        m_scene = build(context(), settings, options, camera());
        set_output(m_scene.output);
        m_pinhole = pinhole_camera(m_scene.camera, settings.aspect());
        start_at(m_scene.camera, m_pinhole);
        reset();
    }

    bool progressive() const override { return true; }
    bool denoises() const override { return true; }

    void set_denoiser(ViewDenoiser denoiser) override {
        if (denoiser != ViewDenoiser::kOff && !m_denoisers)
            m_denoisers.emplace(context(), settings(), kGBufferRay, kGBufferEntry,
                                camera().buffer(), m_scene.output, m_scene.materials);
        if (denoiser == m_denoiser) return;
        m_denoiser = denoiser;
        reset();
    }

    void set_camera(const scene::Camera& camera) override {
        m_pinhole = pinhole_camera(camera, settings().aspect());
        this->camera().set(m_pinhole);
        clear_accumulation();  // SVGF keeps its history: it reprojects it
        m_resting = 0;
    }

    void reset() override {
        clear_accumulation();
        m_resting = 0;
        if (m_denoisers) m_denoisers->reset_history();
    }

    FrameResult frame() override {
        if (m_denoiser == ViewDenoiser::kOff) {
            FrameResult out = CameraSession::frame();
            out.samples = ++m_samples;
            return out;
        }
        // SVGF: a new sample per pixel, on streams of its own, for SVGF to integrate.
        if (m_denoiser == ViewDenoiser::kSvgf && m_samples > 0) clear_accumulation();
        RenderResult passes;
        context().launch(0, settings().width, settings().height);
        passes.report = context().last_launch();
        add_launch_stages(passes.report, passes.stages);
        const Buffer& filtered = m_denoisers->run(m_denoiser, m_pinhole, passes);
        FrameResult out = frame_of(std::move(passes), filtered);
        ++m_samples;
        // SVGF: the frames since the camera last moved, which its resting history averages.
        out.samples = m_denoiser == ViewDenoiser::kSvgf ? ++m_resting : m_samples;
        return out;
    }

  private:
    bool apply_options(const OptionValues& values) override {
        set_variables(*m_scene.camera_program, *m_scene.miss, PathOptions(values));
        return true;
    }

    void clear_accumulation() {
        // The sample count is the accumulation's w: zero restarts the average (and the
        // random streams, so a resting camera converges to the sample's own render).
        // SVGF's frames go on from the streams used so far instead.
        const unsigned streams = m_denoiser == ViewDenoiser::kSvgf ? m_streams + m_samples : 0;
        if (streams != m_streams) {
            m_streams = streams;
            m_scene.stream_offset->upload(std::vector<unsigned>{m_streams});
        }
        const size_t pixels = size_t(settings().width) * settings().height;
        m_scene.accum->upload(std::vector<float4>(pixels, make_float4(0.0f, 0.0f, 0.0f, 0.0f)));
        m_samples = 0;
    }

    PathScene m_scene;
    sample_common::PinholeCamera m_pinhole{};
    unsigned m_samples = 0;  // in the accumulation buffer
    unsigned m_streams = 0;  // SVGF: sample streams used before the accumulation's
    unsigned m_resting = 0;  // SVGF: frames since the camera moved
    ViewDenoiser m_denoiser = ViewDenoiser::kOff;
    std::optional<ViewDenoisers> m_denoisers;
};

class PathtracerSample final : public Sample {
  public:
    PathtracerSample()
        : Sample("pathtracer",
                 "Progressive path tracer (OptiX paper §6.2): the bounce loop in ray generation, "
                 "Lambert, GGX metal, glass and coated materials, next-event estimation with "
                 "MIS, Russian roulette; --spp frames averaged (default 64); try --scene "
                 "cornell-materials",
                 {
                     SampleOption::integer("max_depth", 8, 1, 256, "path segments from the eye"),
                     SampleOption::integer("rr_depth", 3, 1, 256,
                                           "bounces before Russian roulette starts"),
                     SampleOption::toggle("nee", true,
                                          "1: light sampling with MIS, 0: BSDF sampling only"),
                     SampleOption::number("environment", 0.0f, 0.0f, 1e6f,
                                          "uniform radiance of every ray that escapes"),
                     SampleOption::number("exposure", 1.0f, 0.0f, 1e6f, "multiplies the image"),
                     SampleOption::toggle(
                         "reinhard", false,
                         "1: Reinhard tone mapping L / (1 + L) after the exposure"),
                     SampleOption::integer("seed", 0, 0, 1 << 30,
                                           "selects an independent set of random streams"),
                 }) {}

    bool writes_aovs() const override { return true; }

    RenderResult render(const RenderSettings& settings) const override {
        const PathOptions options(read_options(settings));
        const Clock::time_point setup_start = Clock::now();
        Context ctx(settings.context_options());
        RenderResult out = result_for(ctx);
        CameraBuffer camera(ctx);
        AovPasses aovs(ctx, settings, kGBufferRay, kGBufferEntry, camera.buffer());
        const PathScene scene = build(ctx, settings, options, camera, &aovs);
        aovs.set_colour(scene.output);
        const sample_common::PinholeCamera pinhole = pinhole_camera(scene.camera, settings.aspect());
        camera.set(pinhole);
        out.camera = scene.camera;
        out.stages.push_back({"scene setup", ms_since(setup_start), scene.note});
        render_frames(ctx, settings, out);
        out.image = image_from_output(*scene.output);
        aovs.finish(pinhole, out);
        return out;
    }

    std::unique_ptr<InteractiveSession> open(const RenderSettings& settings) const override {
        return std::make_unique<PathSession>(*this, settings, PathOptions(read_options(settings)));
    }
};

const RegisterSample<PathtracerSample> kRegistered(/*help_order=*/50);

}  // namespace
}  // namespace lucent::samples

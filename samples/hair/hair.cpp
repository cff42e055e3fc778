// The hair sample: a head of hair (built-in curves) on a head mesh, built-in spheres and a
// ground plane, rendered by the path tracer (its camera, miss and materials: pathtracer::
// shade) with light linking through visibility masks (samples/hair/hair_programs.h). Its
// scene is built in code (hair_scene.h): --scene is refused. `lucent view` accumulates one
// sample per pixel per frame while the camera rests, as the path tracer's session does.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "samples/camera_session.h"
#include "samples/hair/hair_programs.h"
#include "samples/hair/hair_scene.h"
#include "samples/nearest_name.h"
#include "samples/progressive_frames.h"
#include "samples/scene_setup.h"
#include "samples/settings_error.h"
#include "samples/stages.h"

namespace lucent::samples {

namespace {

/// The sample's --set options, checked (and --scene and --camera refused).
struct HairOptions {
    HairShape shape;
    bool light_linking = true;
    int max_depth = 8, rr_depth = 3, seed = 0;
    float environment = 0, exposure = 1;

    HairOptions(const OptionValues& v, const RenderSettings& settings)
        : light_linking(v.on("light_linking")),
          max_depth(v.integer("max_depth")),
          rr_depth(v.integer("rr_depth")),
          seed(v.integer("seed")),
          environment(v.number("environment")),
          exposure(v.number("exposure")) {
        shape.strands = unsigned(v.integer("strands"));
        const std::string& type = v.text("curve_type");
        const std::optional<CurveType> named = scene::curve_type_named(type);
        if (!named) {
            std::string names;
            for (const std::string& n : scene::curve_type_names())
                names += (names.empty() ? "" : ", ") + n;
            throw SettingsError("--set curve_type=" + type + ": no such curve type" +
                                did_you_mean(type, scene::curve_type_names()) + "; the types are " +
                                names);
        }
        shape.type = *named;
        if (!settings.scene.empty())
            throw SettingsError("--scene " + settings.scene +
                                ": the hair sample renders its own scene, built in code; "
                                "leave --scene out");
        if (settings.scene_camera)
            throw SettingsError("--camera " + std::to_string(*settings.scene_camera) +
                                ": the hair sample's scene has 0 cameras of its own (its "
                                "camera is built in); move it with --eye --look --up --fov");
    }
};

/// Sets the options that are variables: of the camera program and of the miss program.
void set_variables(Program& camera, Program& miss, const HairOptions& o) {
    camera["max_depth"] = unsigned(o.max_depth);
    camera["rr_depth"] = unsigned(o.rr_depth);
    camera["nee"] = 1u;
    camera["seed"] = unsigned(o.seed);
    camera["exposure"] = o.exposure;
    camera["reinhard"] = 0u;
    miss["environment"] = make_float3(o.environment);
}

/// What build() made that the render loop and the session need.
struct HairRender {
    scene::Camera camera;  // the scene's, with --eye --look --up --fov applied
    HairSceneData data;
    HairGraph graph;
    std::shared_ptr<Buffer> accum, output;  // width x height float4
    std::shared_ptr<Program> camera_program, miss;
    std::string note;  // "hair: 48000 cubic segments, ..."
};

/// Builds the scene into `ctx` with the path tracer's camera program at entry 0, reading
/// `camera`.
HairRender build(Context& ctx, const RenderSettings& settings, const HairOptions& options,
                 const CameraBuffer& camera) {
    HairRender out;
    out.data = make_hair_scene(options.shape);
    out.camera = settings.camera.applied_to(out.data.meshes.camera);  // checks the camera

    ctx.set_ray_type<pathtracer::PathPayload>(pathtracer::kRadianceRay, "radiance");
    ctx.set_ray_type<pathtracer::ShadowPayload>(pathtracer::kShadowRay, "shadow",
                                                /*expects_closest_hit=*/false);
    ctx.set_max_recursion_depth(2);  // the path loop's rays, then shadow rays from hits
    out.graph = build_hair_graph(ctx, out.data, options.light_linking);

    out.accum =
        ctx.create_buffer<float4>(BufferType::kInputOutput, settings.width, settings.height);
    out.output = ctx.create_buffer<float4>(BufferType::kOutput, settings.width, settings.height);
    auto stream_offset = ctx.create_buffer<unsigned>(BufferType::kInput, 1);
    stream_offset->upload(std::vector<unsigned>{0});
    out.miss = ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_miss));
    ctx.set_miss_program(pathtracer::kRadianceRay, out.miss);
    out.camera_program = ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_camera));
    (*out.camera_program)["camera"] = camera.buffer();
    (*out.camera_program)["accum"] = out.accum;
    (*out.camera_program)["output"] = out.output;
    (*out.camera_program)["stream_offset"] = stream_offset;
    set_variables(*out.camera_program, *out.miss, options);
    ctx.set_ray_generation_program(0, out.camera_program);
    out.note = "hair, " + std::to_string(out.data.hair.segments.size()) + " " +
               scene::curve_type_names()[options.shape.type] + " segments, " +
               std::to_string(out.data.spheres.size()) + " spheres, " +
               std::to_string(out.data.meshes.triangle_count()) + " triangles; light linking " +
               (options.light_linking ? "on" : "off");
    return out;
}

void clear(Buffer& accum, const RenderSettings& settings) {
    const size_t pixels = size_t(settings.width) * settings.height;
    accum.upload(std::vector<float4>(pixels, make_float4(0.0f, 0.0f, 0.0f, 0.0f)));
}

/// `lucent view`: progressive; moving the camera or changing an option restarts the
/// accumulation (its w, the frame number, back to 0). The scene's shape (strands, curve
/// type) rebuilds the session; the rest are variables and the light masks' buffer.
class HairSession final : public CameraSession {
  public:
    HairSession(const Sample& sample, const RenderSettings& settings, const HairOptions& options)
        : CameraSession(sample, settings), m_shape(options.shape) {
        m_render = build(context(), settings, options, camera());
        set_output(m_render.output);
        start_at(m_render.camera, pinhole_camera(m_render.camera, settings.aspect()));
        reset();
    }

    bool progressive() const override { return true; }

    void reset() override {
        clear(*m_render.accum, settings());
        m_samples = 0;
    }

    FrameResult frame() override {
        FrameResult out = CameraSession::frame();
        out.samples = ++m_samples;
        return out;
    }

  private:
    bool apply_options(const OptionValues& values) override {
        const HairOptions options(values, settings());
        if (options.shape.strands != m_shape.strands || options.shape.type != m_shape.type)
            return false;
        set_variables(*m_render.camera_program, *m_render.miss, options);
        m_render.graph.light_masks->upload(
            light_masks(m_render.data.meshes, options.light_linking));
        return true;
    }

    HairShape m_shape;
    HairRender m_render;
    unsigned m_samples = 0;
};

class HairSample final : public Sample {
  public:
    HairSample()
        : Sample("hair",
                 "A head of hair (built-in cubic B-spline curves) on a head mesh, built-in "
                 "spheres and a ground plane, path traced with the path tracer's materials; "
                 "light linking through visibility masks: the key light's shadow rays leave "
                 "the hair out (light_linking=0: they do not); --spp frames (default 64)",
                 {
                     SampleOption::integer("strands", 4000, 0, 200000,
                                           "strands of 12 curve segments on the head"),
                     SampleOption::text("curve_type", "cubic",
                                        "the strands' curves: linear, quadratic, cubic "
                                        "(B-splines) or catmull-rom"),
                     SampleOption::toggle("light_linking", true,
                                          "1: the hair casts no shadow from the key light "
                                          "(its shadow rays' mask leaves the hair out), 0: "
                                          "every light is shadowed by everything"),
                     SampleOption::integer("max_depth", 8, 1, 256, "path segments from the eye"),
                     SampleOption::integer("rr_depth", 3, 1, 256,
                                           "bounces before Russian roulette starts"),
                     SampleOption::number("environment", 0.1f, 0.0f, 1e6f,
                                          "uniform radiance of every ray that escapes"),
                     SampleOption::number("exposure", 1.0f, 0.0f, 1e6f, "multiplies the image"),
                     SampleOption::integer("seed", 0, 0, 1 << 30,
                                           "selects an independent set of random streams"),
                 }) {}

    RenderResult render(const RenderSettings& settings) const override {
        const HairOptions options(read_options(settings), settings);
        const Clock::time_point setup_start = Clock::now();
        Context ctx(settings.context_options());
        RenderResult out = result_for(ctx);
        CameraBuffer camera(ctx);
        const HairRender scene = build(ctx, settings, options, camera);
        camera.set(pinhole_camera(scene.camera, settings.aspect()));
        clear(*scene.accum, settings);
        out.camera = scene.camera;
        out.stages.push_back({"scene setup", ms_since(setup_start), scene.note});
        render_progressive(ctx, settings, /*default_spp=*/64, out);
        out.image = image_from_output(*scene.output);
        return out;
    }

    std::unique_ptr<InteractiveSession> open(const RenderSettings& settings) const override {
        return std::make_unique<HairSession>(*this, settings,
                                             HairOptions(read_options(settings), settings));
    }
};

const RegisterSample<HairSample> kRegistered(/*help_order=*/55);

}  // namespace
}  // namespace lucent::samples

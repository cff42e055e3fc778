// Host setup of the IGI sample: the scene as triangles with per-triangle materials, its
// lights as point emitters, for the paper's form of imperfect visibility a second graph of
// per-triangle boxes,
// and the passes of the IGI paper's Fig. 3 as entry points launched in order each frame. `lucent view`
// runs the same frame, the camera in a buffer.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "samples/aov_passes.h"
#include "samples/camera_session.h"
#include "samples/igi/igi_frames.h"
#include "samples/igi/igi_programs.h"
#include "samples/scene_setup.h"
#include "samples/settings_error.h"
#include "samples/stages.h"
#include "scene/scene.h"

namespace lucent::samples {

namespace {

/// The scene's lights as IGI's point emitters: point lights as they are; each area light
/// (declared, or an emissive triangle) as a side x side grid of cosine lobes at its cells'
/// centres (sample_common::light_point's equal-area cells), sharing its power L A pi, each
/// moved off the light's surface (sample_common::offset_ray_origin) so that a shadow ray
/// towards it, or a particle leaving it, does not meet the light's own triangles.
std::vector<igi::PointEmitter> point_emitters(const scene::Scene& input, int side) {
    const float size = scene_size(input);
    std::vector<igi::PointEmitter> lights;
    for (const auto& l : input.point_lights)
        lights.push_back({l.position, l.intensity, make_float3(0.0f)});
    for (const sample_common::AreaLight& a : area_lights(input)) {
        const float area = sample_common::light_area(a);
        if (!(area > 0.0f)) continue;  // degenerate: emits nothing
        const float3 normal = sample_common::light_normal(a);
        const float cells = float(side * side);
        for (int j = 0; j < side; ++j)
            for (int i = 0; i < side; ++i) {
                const float u = (float(i) + 0.5f) / float(side),
                            v = (float(j) + 0.5f) / float(side);
                lights.push_back(
                    {sample_common::offset_ray_origin(sample_common::light_point(a, u, v), normal,
                                                      size),
                     a.emission * (area / cells), normal});
            }
    }
    return lights;
}

/// The light paths shared among the emitters in proportion to their flux (summed over the
/// colour channels): path p starts at the emitter whose share of the cumulative flux holds
/// (p + 1/2) / paths, so an emitter of a fraction f of the flux starts about f x paths of
/// them, a run of consecutive paths, each carrying its flux over its own path count (equal
/// emitters start equally many, as the paper's round of the lights). An emitter of less than
/// half a path's share may start none.
std::vector<igi::LightPath> light_paths(const std::vector<igi::PointEmitter>& lights,
                                        unsigned paths) {
    std::vector<double> cumulative;
    double total = 0;
    for (const auto& l : lights) {
        const float3 f = igi::flux(l);
        total += std::max(0.0f, f.x + f.y + f.z);
        cumulative.push_back(total);
    }
    std::vector<igi::LightPath> out(paths);
    std::vector<unsigned> count(lights.size(), 0);
    for (unsigned p = 0; p < paths; ++p) {
        unsigned e = unsigned(p % lights.size());  // no flux anywhere: take turns
        if (total > 0) {
            const double u = (p + 0.5) / paths * total;
            e = unsigned(std::upper_bound(cumulative.begin(), cumulative.end(), u) -
                         cumulative.begin());
            e = std::min(e, unsigned(lights.size() - 1));
        }
        out[p].emitter = e;
        out[p].sequence = ++count[e];
    }
    for (auto& path : out) path.flux = igi::flux(lights[path.emitter]) / float(count[path.emitter]);
    return out;
}

/// Each triangle's bounding box, lo and hi (two float4), for the boxes graph of imperfect
/// visibility (igi::BoxRecord).
std::shared_ptr<Buffer> triangle_boxes(Context& ctx, const scene::Mesh& mesh) {
    std::vector<float4> boxes;
    boxes.reserve(2 * mesh.indices.size());
    for (const uint3& t : mesh.indices) {
        const float3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
        boxes.push_back(make_float4(fminf(a, fminf(b, c)), 0.0f));
        boxes.push_back(make_float4(fmaxf(a, fmaxf(b, c)), 0.0f));
    }
    auto buffer = ctx.create_buffer<float4>(BufferType::kInput, unsigned(boxes.size()));
    buffer->upload(boxes);
    return buffer;
}

/// The most texels the VPLs' visibility maps may take together (4 bytes each: 1 GiB).
constexpr unsigned long long kMaxMapTexels = 1ull << 28;

/// Each VPL's visibility map is a buffer of its own texels: refuses what would not fit.
void check_map_memory(const IgiConfig& config) {
    const unsigned long long side = config.visibility_map;
    const unsigned long long texels = side * side * config.paths * config.bounces;
    if (texels > kMaxMapTexels)
        throw SettingsError("--set visibility_map=" + std::to_string(side) + ": " +
                            std::to_string(config.paths * config.bounces) + " VPLs' maps of " +
                            std::to_string(side) + "x" + std::to_string(side) + " texels need " +
                            std::to_string(texels * 4 >> 20) +
                            " MiB, over the 1024 MiB allowed; use a smaller visibility_map, "
                            "or fewer vpls or bounces");
}

/// The sample's --set options, checked: the frame's configuration and the variables.
struct IgiOptions {
    IgiConfig config;
    float min_d_fraction, depth_threshold, normal_threshold, sigma;
    int max_depth, imperfect, area_side;

    IgiOptions(const OptionValues& v, const RenderSettings& settings)
        : min_d_fraction(v.number("min_d")),
          depth_threshold(v.number("depth_threshold")),
          normal_threshold(v.number("normal_threshold")),
          sigma(v.number("sigma")),
          max_depth(v.integer("max_depth")),
          imperfect(v.integer("imperfect_visibility")),
          area_side(v.integer("area_samples")) {
        config.paths = unsigned(v.integer("vpls"));
        config.bounces = unsigned(v.integer("bounces"));
        config.downsample = unsigned(v.integer("downsample"));
        config.interleave = unsigned(v.integer("interleave"));
        config.layers = v.on("reflection_layer") ? 2u : 1u;
        if (imperfect == igi::kVisibilityMapVisibility) {
            config.visibility_map = unsigned(v.integer("visibility_map"));
            check_map_memory(config);
        }
        config.width = settings.width;
        config.height = settings.height;
        const int slices = v.integer("vpl_slices");
        config.slices = slices > 0 ? unsigned(slices) : auto_indirect_slices(config);
    }
};

/// The visibility-only ray types, the recursion depth and the context-wide variables. The
/// radiance and particle ray types follow with the graph they trace (add_graphs).
void set_up_context(Context& ctx, const IgiOptions& o, float size) {
    ctx.set_ray_type<igi::ShadowPayload>(igi::kShadowRay, "shadow", /*expects_closest_hit=*/false);
    ctx.set_ray_type<igi::ShadowPayload>(igi::kVplShadowRay, "vpl shadow",
                                         /*expects_closest_hit=*/false);
    ctx.set_max_recursion_depth(unsigned(o.max_depth) + 1);
    ctx["scene_size"] = size;
    ctx["min_d"] = o.min_d_fraction * size;
    ctx["max_depth"] = unsigned(o.max_depth);
    ctx["bounces"] = o.config.bounces;
    ctx["downsample"] = o.config.downsample;
    ctx["interleave"] = o.config.interleave;
    ctx["reflection_layer"] = o.config.layers > 1 ? 1u : 0u;
    ctx["slices"] = o.config.slices;
    ctx["depth_threshold"] = o.depth_threshold;
    ctx["normal_threshold"] = o.normal_threshold;
    ctx["sigma"] = o.sigma;
    ctx["imperfect_visibility"] = unsigned(o.imperfect);
}

/// The point emitters, where each light path starts, and the VPL buffer their particles fill.
void add_lights(Context& ctx, const std::vector<igi::PointEmitter>& lights, const IgiConfig& config) {
    auto light_buffer =
        ctx.create_buffer<igi::PointEmitter>(BufferType::kInput, unsigned(lights.size()));
    light_buffer->upload(lights);
    ctx["lights"] = light_buffer;
    const std::vector<igi::LightPath> paths = light_paths(lights, config.paths);
    auto path_buffer = ctx.create_buffer<igi::LightPath>(BufferType::kInput, unsigned(paths.size()));
    path_buffer->upload(paths);
    ctx["light_paths"] = path_buffer;
    const unsigned vpls = config.paths * config.bounces;
    ctx["vpls"] = ctx.create_buffer<igi::Vpl>(BufferType::kInputOutput, vpls);
    // Each VPL's visibility map (imperfect_visibility=3); one texel when there are none, so
    // that the variable is bound.
    const unsigned map = config.visibility_map;
    ctx["vpl_maps"] = map > 0 ? ctx.create_buffer<float>(BufferType::kInputOutput, map, map, vpls)
                              : ctx.create_buffer<float>(BufferType::kInputOutput, 1, 1, 1);
}

/// The scene's triangles ("top_object", traced by radiance and particle rays) and, for the
/// paper's form of imperfect visibility (IGI paper §4.1, imperfect_visibility=2), a second
/// graph of one box per triangle as custom primitives ("vpl_shadow_object", traced only by
/// VPL shadow rays; an empty group otherwise).
void add_graphs(Context& ctx, const scene::Scene& input, bool box_graph, AovPasses* aovs) {
    auto surface = ctx.create_program(LUCENT_PROGRAM(igi::igi_surface));
    auto particle = ctx.create_program(LUCENT_PROGRAM(igi::igi_particle_hit));
    auto depth = ctx.create_program(LUCENT_PROGRAM(igi::igi_depth_hit));
    DiffuseTextures texture_for(ctx, &input);
    std::vector<std::shared_ptr<Material>> materials;
    for (const auto& m : input.materials) {
        auto material = ctx.create_material();
        material->set_name(m.name);
        material->set_closest_hit(igi::kRadianceRay, surface);
        material->set_closest_hit(igi::kParticleRay, particle);
        material->set_closest_hit(igi::kVplDepthRay, depth);
        // Glass is the specular tree's refraction and reflection only (igi::dielectric):
        // neither diffuse nor a mirror, and particles stop at it (no VPL: no albedo).
        const bool glass = m.kind == scene::MaterialKind::kDielectric;
        (*material)["Kd"] = glass ? make_float3(0.0f) : m.diffuse;
        (*material)["Ks"] = glass ? make_float3(0.0f) : m.specular;
        (*material)["Ke"] = m.emission;
        (*material)["ior"] = glass ? m.ior : 0.0f;
        (*material)["diffuse_map"] = texture_for(m.diffuse_texture);
        materials.push_back(material);
    }
    auto attributes = ctx.create_program(LUCENT_PROGRAM(sample_common::mesh_normal_uv));
    std::vector<std::shared_ptr<GeometryInstance>> box_instances;  // per mesh, as the scene's
    auto box_bounds = ctx.create_program(LUCENT_PROGRAM(igi::igi_triangle_box_bounds));
    auto box_intersect = ctx.create_program(LUCENT_PROGRAM(igi::igi_triangle_box_intersect));
    auto box_material = ctx.create_material();  // occlusion queries run no hit programs
    box_material->set_name("box");
    auto add_boxes = [&](const scene::Mesh& mesh, const MeshBuffers&) {
        if (!box_graph) return;
        auto box_geometry = ctx.create_geometry();
        box_geometry->set_primitive_count(unsigned(mesh.indices.size()));
        box_geometry->set_bounding_box_program(box_bounds);
        box_geometry->set_intersection_program(box_intersect);
        (*box_geometry)["boxes"] = triangle_boxes(ctx, mesh);
        auto box_instance = ctx.create_geometry_instance();
        box_instance->set_geometry(box_geometry);
        box_instance->add_material(box_material);
        box_instances.push_back(box_instance);
    };
    auto top = mesh_group(ctx, input, attributes, materials, add_boxes);
    // The boxes are in object space like the triangles, placed by the same instances.
    std::shared_ptr<Node> boxes = box_graph ? place_meshes(ctx, input, box_instances)
                                            : std::shared_ptr<Node>(ctx.create_geometry_group());
    ctx["top_object"] = top;
    ctx["vpl_shadow_object"] = boxes;
    // Radiance and particle rays trace the scene; the boxes need none of their programs.
    ctx.set_ray_type<igi::RadiancePayload>(igi::kRadianceRay, "radiance", true, {top});
    ctx.set_ray_type<igi::ParticlePayload>(igi::kParticleRay, "particle", true, {top});
    ctx.set_ray_type<igi::DepthPayload>(igi::kVplDepthRay, "vpl depth", true, {top});
    if (aovs) aovs->add_to(materials, {top});  // G-buffer rays trace the scene, not the boxes
}

/// The passes of the IGI paper's Fig. 3 as entry points, each reading and writing its images.
void add_passes(Context& ctx, const IgiConfig& config, const IgiImages& images,
                const CameraBuffer& camera_buffer) {
    auto camera = ctx.create_program(LUCENT_PROGRAM(igi::igi_camera));
    (*camera)["camera"] = camera_buffer.buffer();
    auto indirect = ctx.create_program(LUCENT_PROGRAM(igi::igi_indirect));
    (*indirect)["indirect"] = config.slices > 1 ? images.indirect_slices : images.indirect;
    auto indirect_sum = ctx.create_program(LUCENT_PROGRAM(igi::igi_indirect_sum));
    (*indirect_sum)["indirect_slices"] = images.indirect_slices;
    (*indirect_sum)["indirect"] = images.indirect;
    auto discontinuity = ctx.create_program(LUCENT_PROGRAM(igi::igi_discontinuity));
    (*discontinuity)["indirect"] = images.indirect;
    (*discontinuity)["merged"] = images.merged;
    auto upsample = ctx.create_program(LUCENT_PROGRAM(igi::igi_upsample));
    (*upsample)["low"] = config.interleave > 1 ? images.merged : images.indirect;
    (*upsample)["full"] = images.upsampled;
    auto compose = ctx.create_program(LUCENT_PROGRAM(igi::igi_compose));
    (*compose)["indirect"] = images.irradiance_at_full_resolution(config);
    (*compose)["output"] = images.output;
    // At least the sample's own: the AOV passes' entry points may follow them.
    ctx.set_entry_point_count(std::max(ctx.entry_point_count(), unsigned(igi::kEntryCount)));
    ctx.set_ray_generation_program(igi::kDirectEntry, camera);
    ctx.set_ray_generation_program(igi::kVplEntry,
                                   ctx.create_program(LUCENT_PROGRAM(igi::igi_generate_vpls)));
    ctx.set_ray_generation_program(igi::kIndirectEntry, indirect);
    ctx.set_ray_generation_program(igi::kDiscontinuityEntry, discontinuity);
    ctx.set_ray_generation_program(igi::kUpsampleEntry, upsample);
    ctx.set_ray_generation_program(igi::kComposeEntry, compose);
    ctx.set_ray_generation_program(igi::kIndirectSumEntry, indirect_sum);
    ctx.set_ray_generation_program(igi::kVplMapEntry,
                                   ctx.create_program(LUCENT_PROGRAM(igi::igi_vpl_maps)));
    ctx.set_miss_program(igi::kRadianceRay, ctx.create_program(LUCENT_PROGRAM(igi::igi_miss)));
}

/// The intermediate images, for tests (RenderSettings::keep_layers).
void keep_layers(const IgiConfig& config, const IgiImages& images, RenderResult& out) {
    out.layers["direct"] = image_from_output(*images.direct);
    out.layers["albedo"] = image_from_output(*images.gbuffer_albedo);
    out.layers["normal"] = image_from_output(*images.gbuffer_normal);
    out.layers["position"] = image_from_output(*images.gbuffer_position);
    out.layers["indirect"] = image_from_output(*images.irradiance_at_full_resolution(config));
    out.layers["indirect_low"] = image_from_output(*images.indirect);
    if (config.layers > 1) {  // the first reflected hits (the reflection layer)
        out.layers["reflected_weight"] = image_from_output(*images.gbuffer_albedo, 1);
        out.layers["reflected_indirect"] =
            image_from_output(*images.irradiance_at_full_resolution(config), 1);
    }
}

/// What a render and a session build: the scene of settings.scene (default: cornell) in
/// `ctx` with its point emitters, the images of the IGI paper's Fig. 3 (full resolution G-buffer and
/// direct image, the indirect irradiance at 1/N resolution, merged, and upsampled) and the
/// passes, the camera reading `camera`.
struct IgiScene {
    scene::Scene input;
    std::vector<igi::PointEmitter> lights;
    IgiImages images;

    IgiScene(Context& ctx, const RenderSettings& settings, const IgiOptions& options,
             const CameraBuffer& camera, AovPasses* aovs = nullptr)
        : input(load_render_scene(settings)),
          lights(point_emitters(input, options.area_side)) {
        if (lights.empty())
            throw SettingsError("igi: scene '" + input.name +
                                "' has no lights; IGI traces its particles from point and area "
                                "lights and emissive triangles (try --scene cornell, give a "
                                "material Ke in its MTL, or add a light to a JSON scene)");
        set_up_context(ctx, options, scene_size(input));
        add_lights(ctx, lights, options.config);
        add_graphs(ctx, input, options.imperfect == igi::kBoxGraphVisibility, aovs);
        images = create_igi_images(ctx, options.config);
        add_passes(ctx, options.config, images, camera);
    }
};

/// `lucent view`: the scene built once, its frame (the passes of Fig. 3) launched again when
/// the camera moves. The options are variables baked at build time or size its buffers, so
/// an option rebuilds the scene.
class IgiSession final : public CameraSession {
  public:
    IgiSession(const Sample& sample, const RenderSettings& settings, const IgiOptions& options)
        : CameraSession(sample, settings),
          m_config(options.config),
          m_scene(context(), settings, options, camera()) {
        start_at(m_scene.input.camera, pinhole_camera(m_scene.input.camera, settings.aspect()));
    }

    FrameResult frame() override {
        RenderSettings once = settings();
        once.repeat = 1;
        once.progress = nullptr;
        RenderResult passes;
        render_igi_frames(context(), m_config, once, passes);
        return frame_of(std::move(passes), *m_scene.images.output);
    }

  private:
    IgiConfig m_config;
    IgiScene m_scene;
};

class IgiSample final : public Sample {
  public:
    IgiSample()
        : Sample(
              "igi",
              "Instant Global Illumination (Marques and Santos, §4): VPLs from the lights "
              "along Halton paths, direct light, specular reflections, Eq. (1), and the paper's "
              "three accelerations",
              {
                  SampleOption::integer("vpls", 180, 1, 65536, "light paths traced from the lights"),
                  SampleOption::integer("bounces", 1, 1, 8,
                                        "VPLs per path: diffuse bounces recorded"),
                  SampleOption::number(
                      "min_d", 0.1f, 0.0f, 10.0f,
                      "Eq. (1)'s bounding distance, as a fraction of the scene's size"),
                  SampleOption::integer(
                      "max_depth", 4, 1, 16,
                      "deepest specular tree (mirrors; glass reflects and refracts)"),
                  SampleOption::integer(
                      "imperfect_visibility", 0, 0, 3,
                      "VPL visibility (IGI paper §4.1): shadow rays against 0: the triangles; "
                      "1: the boxes of the scene BVH's leaves; 2: the paper's second graph of "
                      "one box per triangle; or 3: a depth map per VPL, no shadow rays"),
                  SampleOption::integer(
                      "visibility_map", 64, 4, 1024,
                      "imperfect_visibility=3: each VPL's depth map is this many texels "
                      "square (one ray each)"),
                  SampleOption::integer(
                      "downsample", 1, 1, 16,
                      "N: indirect light at 1/N of the resolution, joint bilateral upsampling"),
                  SampleOption::integer("interleave", 1, 1, 8,
                                        "M: VPLs split into M x M subsets over M x M pixel "
                                        "tiles, merged by the discontinuity buffer"),
                  SampleOption::integer("vpl_slices", 0, 0, 64,
                                        "threads sharing a pixel's VPLs in the indirect pass; 0: "
                                        "as many as give about 2^20 work items"),
                  SampleOption::toggle(
                      "reflection_layer", true,
                      "1: the first reflected hit's indirect light is a G-buffer layer of its own, "
                      "downsampled and interleaved like the primary hit's; 0: inline, as in the "
                      "paper"),
                  SampleOption::number(
                      "depth_threshold", 0.1f, 0.0f, 10.0f,
                      "discontinuity buffer: largest relative depth difference of neighbours"),
                  SampleOption::number(
                      "normal_threshold", 0.9f, -1.0f, 1.0f,
                      "discontinuity buffer: smallest cosine between neighbours' normals"),
                  SampleOption::number(
                      "sigma", 1.0f, 0.1f, 16.0f,
                      "upsampling: spatial Gaussian's sigma in low-resolution pixels"),
                  SampleOption::integer("area_samples", 4, 1, 64,
                                        "each area light becomes a side x side grid of point "
                                        "emitters; the side"),
              }) {}

    RenderResult render(const RenderSettings& settings) const override {
        const IgiOptions options(read_options(settings), settings);
        const Clock::time_point setup_start = Clock::now();
        Context ctx(settings.context_options());
        RenderResult out = result_for(ctx);
        CameraBuffer camera(ctx);
        // The G-buffer's ray type and entry points come after the sample's own.
        AovPasses aovs(ctx, settings, igi::kVplDepthRay + 1, igi::kEntryCount, camera.buffer());
        const IgiScene scene(ctx, settings, options, camera, &aovs);
        aovs.set_colour(scene.images.output);
        const sample_common::PinholeCamera pinhole =
            pinhole_camera(scene.input.camera, settings.aspect());
        camera.set(pinhole);
        out.camera = scene.input.camera;
        out.stages.push_back({"scene setup", ms_since(setup_start),
                              scene_note(scene.input) + ", " +
                                  std::to_string(scene.lights.size()) + " point emitters"});
        render_igi_frames(ctx, options.config, settings, out);
        out.image = image_from_output(*scene.images.output);
        if (settings.keep_layers) keep_layers(options.config, scene.images, out);
        aovs.finish(pinhole, out);
        return out;
    }

    bool writes_aovs() const override { return true; }

    std::unique_ptr<InteractiveSession> open(const RenderSettings& settings) const override {
        return std::make_unique<IgiSession>(*this, settings, IgiOptions(read_options(settings), settings));
    }
};

const RegisterSample<IgiSample> kRegistered(/*help_order=*/30);

}  // namespace
}  // namespace lucent::samples

// Host setup of the path tracer: the scene's triangles with one Material per scene material
// (its closest hit chosen by MaterialKind), the area and point lights in buffers, and the
// progressive loop: one launch per sample per pixel into the accumulation buffer.
#include "samples/pathtracer/pathtracer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "samples/pathtracer/pathtracer_programs.h"
#include "samples/pathtracer/pathtracer_scene.h"
#include "samples/scene_setup.h"
#include "scene/scene.h"

namespace lucent::samples {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

/// True when an emitting triangle of the scene lies on the light's parallelogram: the light
/// is then geometry that BSDF-sampled rays can hit, as MIS needs.
bool has_geometry(const scene::Scene& s, const scene::AreaLight& light, float tolerance) {
    const float3 normal = cross(light.edge1, light.edge2);
    const float area2 = dot(normal, normal);
    for (const scene::Mesh& mesh : s.meshes)
        for (size_t t = 0; t < mesh.indices.size(); ++t) {
            if (max_component(s.materials[mesh.materials[t]].emission) <= 0) continue;
            const uint3 v = mesh.indices[t];
            const float3 c =
                (mesh.positions[v.x] + mesh.positions[v.y] + mesh.positions[v.z]) / 3.0f;
            const float3 w = c - light.corner;
            const float a = dot(cross(w, light.edge2), normal) / area2;
            const float b = dot(cross(light.edge1, w), normal) / area2;
            if (std::fabs(dot(w, normal)) / std::sqrt(area2) <= tolerance && a >= 0 && a <= 1 &&
                b >= 0 && b <= 1)
                return true;
        }
    return false;
}

/// A light with no emitting surface (a JSON "area" light) becomes a two-triangle emitter,
/// so that the light and BSDF strategies cover the same integral.
void add_light_geometry(scene::Scene& s, float tolerance) {
    for (const scene::AreaLight& light : std::vector<scene::AreaLight>(s.area_lights)) {
        if (has_geometry(s, light, tolerance)) continue;
        scene::Material m{"area light", {0, 0, 0}};
        m.emission = light.emission;
        s.materials.push_back(m);
        scene::Mesh mesh;
        mesh.name = "area light";
        mesh.positions = {light.corner, light.corner + light.edge1,
                          light.corner + light.edge1 + light.edge2, light.corner + light.edge2};
        mesh.indices = {uint3{0, 1, 2}, uint3{0, 2, 3}};
        mesh.materials.assign(2, unsigned(s.materials.size() - 1));
        s.meshes.push_back(std::move(mesh));
    }
}

}  // namespace

PathOptions read_path_options(const RenderSettings& settings) {
    const SampleInfo& info = pathtracer_sample_info();
    check_options(settings, info);
    PathOptions o;
    o.max_depth = get_int_option(settings, info, "max_depth", 1, 256);
    o.rr_depth = get_int_option(settings, info, "rr_depth", 1, 256);
    o.nee = get_int_option(settings, info, "nee", 0, 1);
    o.environment = get_float_option(settings, info, "environment", 0.0f, 1e6f);
    o.exposure = get_float_option(settings, info, "exposure", 0.0f, 1e6f);
    o.reinhard = get_int_option(settings, info, "reinhard", 0, 1);
    o.seed = get_int_option(settings, info, "seed", 0, 1 << 30);
    return o;
}

void set_path_camera_options(Program& camera, const PathOptions& o) {
    camera["max_depth"] = unsigned(o.max_depth);
    camera["rr_depth"] = unsigned(o.rr_depth);
    camera["nee"] = unsigned(o.nee);
    camera["seed"] = unsigned(o.seed);
    camera["exposure"] = o.exposure;
    camera["reinhard"] = unsigned(o.reinhard);
}

PathScene build_path_scene(Context& ctx, const RenderSettings& settings,
                           const PathOptions& options) {
    scene::Scene input = scene::load_scene(settings.scene.empty() ? "cornell" : settings.scene);
    const float extent = scene_extent(input);
    const float epsilon = std::max(1e-4f, 1e-4f * extent);
    add_light_geometry(input, 10 * epsilon);

    ctx.set_ray_type<pathtracer::PathPayload>(pathtracer::kRadianceRay, "radiance");
    ctx.set_ray_type<pathtracer::ShadowPayload>(pathtracer::kShadowRay, "shadow",
                                                /*expects_closest_hit=*/false);
    ctx.set_max_recursion_depth(2);  // the path loop's rays, then shadow rays from hits

    bind_lights<pathtracer::PointLight, pathtracer::AreaLight>(ctx, input);
    ctx["scene_epsilon"] = epsilon;

    std::shared_ptr<Program> closest_hits[] = {
        ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_lambert)),
        ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_metal)),
        ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_dielectric)),
        ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_coated)),
    };
    std::vector<std::shared_ptr<Material>> materials;
    for (const auto& m : input.materials) {
        auto material = ctx.create_material();
        material->set_name(m.name);
        material->set_closest_hit(pathtracer::kRadianceRay, closest_hits[int(m.kind)]);
        (*material)["Kd"] = m.diffuse;
        (*material)["Ks"] = m.specular;
        (*material)["Ke"] = m.emission;
        // Perceptual roughness squared (Burley 2012); a floor keeps GGX finite in float.
        (*material)["alpha"] = std::max(m.roughness * m.roughness, 1e-3f);
        (*material)["ior"] = m.ior;
        materials.push_back(material);
    }
    auto attributes = ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_attributes));
    ctx["top_object"] = mesh_group(ctx, input, attributes, materials);

    PathScene out;
    out.camera = input.camera;
    out.accum =
        ctx.create_buffer<float4>(BufferType::kInputOutput, settings.width, settings.height);
    out.output = ctx.create_buffer<float4>(BufferType::kOutput, settings.width, settings.height);
    out.miss = ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_miss));
    (*out.miss)["environment"] = make_float3(options.environment);
    ctx.set_miss_program(pathtracer::kRadianceRay, out.miss);
    out.note = input.name + ", " + std::to_string(input.triangle_count()) + " triangles";
    return out;
}

namespace {

RenderResult render_pathtracer(const RenderSettings& settings) {
    const PathOptions options = read_path_options(settings);
    const unsigned spp = settings.spp ? settings.spp : 64;
    const Clock::time_point setup_start = Clock::now();
    RenderResult out;
    Context ctx(settings.context_options());
    out.backend = ctx.backend_name();
    out.backend_notice = ctx.backend_notice();
    const PathScene scene = build_path_scene(ctx, settings, options);

    const PinholeFrame frame =
        pinhole_frame(scene.camera, float(settings.width) / float(settings.height));
    auto camera = ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_camera));
    (*camera)["eye"] = scene.camera.eye;
    (*camera)["W"] = frame.W;
    (*camera)["U"] = frame.U;
    (*camera)["V"] = frame.V;
    (*camera)["accum"] = scene.accum;
    (*camera)["output"] = scene.output;
    set_path_camera_options(*camera, options);
    ctx.set_ray_generation_program(0, camera);
    out.stages.push_back({"scene setup", ms_since(setup_start), scene.note});
    auto& output = scene.output;

    // Progressive accumulation: the frame number lives in the accumulation buffer (its w),
    // so launches change nothing on the host and the compiled scene (and on the GPU the
    // megakernel) is reused; a variable per frame would recompile it every frame.
    std::vector<double> frame_ms;
    const Clock::time_point render_start = Clock::now();
    for (unsigned f = 0; f < spp; ++f) {
        ctx.launch(0, settings.width, settings.height);
        const LaunchReport& report = ctx.last_launch();
        if (f == 0) {
            out.report = report;
            add_compile_stages(report, out.stages);
        } else if (report.exception_count() > 0 && out.report.exception_count() == 0) {
            out.report = report;
        }
        frame_ms.push_back(report.launch_ms);
        if (settings.progress) settings.progress(f + 1, spp);
    }
    const double render_ms = ms_since(render_start);
    // The first frame also compiled the scene (and JIT-compiled it): time the others.
    std::vector<double> steady(frame_ms.begin() + (spp > 1 ? 1 : 0), frame_ms.end());
    std::sort(steady.begin(), steady.end());
    const double median = steady[steady.size() / 2];
    char note[200];
    std::snprintf(note, sizeof note, "median of %zu frames (min %.3f, max %.3f)", steady.size(),
                  steady.front(), steady.back());
    out.stages.push_back({"launch (frame)", median, note});
    std::snprintf(note, sizeof note, "%u spp; steady state %.1f samples/pixel/s, %.2f Msamples/s",
                  spp, 1000.0 / median,
                  double(settings.width) * settings.height / (median * 1000.0));
    out.stages.push_back({"render", render_ms, note});
    out.image = image_from_output(*output);
    return out;
}

}  // namespace

const SampleInfo& pathtracer_sample_info() {
    static const SampleInfo info{
        "pathtracer",
        "Progressive path tracer (seed CACM §6.2): the bounce loop in ray generation, Lambert, "
        "GGX metal, glass and coated materials, next-event estimation with MIS, Russian "
        "roulette; --spp frames averaged (default 64); try --scene cornell-materials",
        {
            {"max_depth", "8", "path segments from the eye (1..256)"},
            {"rr_depth", "3", "bounces before Russian roulette starts (1..256)"},
            {"nee", "1", "1: light sampling with MIS, 0: BSDF sampling only"},
            {"environment", "0", "uniform radiance of every ray that escapes (0..1e6)"},
            {"exposure", "1", "multiplies the image (0..1e6)"},
            {"reinhard", "0", "1: Reinhard tone mapping L / (1 + L) after the exposure"},
            {"seed", "0", "selects an independent set of random streams (0..2^30)"},
        },
        render_pathtracer,
        open_pathtracer_session,
    };
    return info;
}

}  // namespace lucent::samples

// The fog sample's scene: geometry and materials of the OptiX SDK tutorial (a tiled floor, a
// rusty reflective box, a glass crystal), two point lights, the environment and the fog box.
#include "samples/fog/fog_scene.h"

#include <cmath>
#include <vector>

#include "lucent/device/tea.h"
#include "samples/fog/fog_programs.h"
#include "samples/scene_setup.h"
#include "scene/texture_image.h"

namespace lucent::samples {

namespace {

constexpr float kFloorHalf = 12.0f;  // the floor (and the fog box) span [-12, 12] in x and z
constexpr float kOrbitStartDegrees = 37.0f;  // where orbit 0 puts the camera
const float3 kLookAt = make_float3(0.0f, 2.0f, 0.0f);

struct Mesh {
    std::vector<float3> positions;
    std::vector<uint3> triangles;
};

/// `m` moved by `placement`.
Mesh placed(Mesh m, const Placement& placement) {
    for (float3& p : m.positions) p = placement.point(p);
    return m;
}

Mesh floor_mesh() {
    const float h = kFloorHalf;
    return {{{-h, 0, -h}, {h, 0, -h}, {h, 0, h}, {-h, 0, h}}, {{0, 2, 1}, {0, 3, 2}}};
}

Mesh box_mesh(float3 lo, float3 hi) {
    Mesh m;
    for (int i = 0; i < 8; ++i)
        m.positions.push_back(
            make_float3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z));
    const unsigned quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                  {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads) {
        m.triangles.push_back(make_uint3(q[0], q[1], q[2]));
        m.triangles.push_back(make_uint3(q[0], q[2], q[3]));
    }
    return m;
}

/// A hexagonal bipyramid standing on its tip: the "translucent crystalline object".
Mesh crystal_mesh(float3 base, float radius) {
    Mesh m;
    const float ring_y[2] = {1.3f, 3.1f};
    for (float y : ring_y)
        for (int k = 0; k < 6; ++k) {
            const float a = 1.0471976f * float(k) + 0.3f;
            m.positions.push_back(base +
                                  make_float3(radius * std::cos(a), y, radius * std::sin(a)));
        }
    m.positions.push_back(base + make_float3(0.0f, 0.05f, 0.0f));  // 12: bottom tip
    m.positions.push_back(base + make_float3(0.0f, 4.6f, 0.0f));   // 13: top tip
    for (unsigned k = 0; k < 6; ++k) {
        const unsigned k1 = (k + 1) % 6;
        m.triangles.push_back(make_uint3(k, k1, 6 + k1));
        m.triangles.push_back(make_uint3(k, 6 + k1, 6 + k));
        m.triangles.push_back(make_uint3(12, k1, k));
        m.triangles.push_back(make_uint3(13, 6 + k, 6 + k1));
    }
    // Wind every face outwards: the glass program tells entering from leaving by the normal.
    float3 centre = make_float3(0.0f);
    for (const float3& p : m.positions) centre += p;
    centre = centre * (1.0f / float(m.positions.size()));
    for (uint3& t : m.triangles) {
        const float3 a = m.positions[t.x], b = m.positions[t.y], c = m.positions[t.z];
        if (dot(cross(b - a, c - a), (a + b + c) * (1.0f / 3.0f) - centre) < 0) std::swap(t.y, t.z);
    }
    return m;
}

/// Ray types, recursion depth, lights and the context-wide variables.
void set_up_context(Context& ctx, const FogOptions& options, const Placement& placement) {
    ctx.set_ray_type<fog::RadiancePayload>(fog::kRadianceRay, "radiance");
    ctx.set_ray_type<fog::ShadowPayload>(fog::kShadowRay, "shadow", /*expects_closest_hit=*/false);
    // Each level of the reflection and refraction tree may cross the fog, whose look behind
    // itself is one more trace at the same depth: two frames per level, and the camera's.
    ctx.set_max_recursion_depth(2 * options.max_depth + 2);

    std::vector<fog::PointLight> lights = {
        {make_float3(-8.0f, 20.0f, -10.0f), make_float3(420.0f, 410.0f, 390.0f)},
        {make_float3(10.0f, 14.0f, 9.0f), make_float3(110.0f, 95.0f, 75.0f)}};
    for (fog::PointLight& light : lights) {
        light.position = placement.point(light.position);
        light.intensity = placement.intensity(light.intensity);
    }
    auto light_buffer =
        ctx.create_buffer<fog::PointLight>(BufferType::kInput, unsigned(lights.size()));
    light_buffer->upload(lights);
    ctx["lights"] = light_buffer;
    ctx["ambient"] = make_float3(0.12f, 0.13f, 0.15f);
    // Secondary rays start off their surface by an offset that follows the scene's size (the
    // floor's side) and the float spacing at the hit (samples/common/ray_offset.h); a fixed
    // 1e-3 was a whole scene at scale 1e-6 and less than a float's spacing at 1e6.
    ctx["scene_size"] = placement.length(2.0f * kFloorHalf);
    // The patterns and the noise are functions of the point relative to the modelled
    // scene's origin, so they move with the scene.
    ctx["model_origin"] = placement.point(make_float3(0.0f));
    ctx["max_depth"] = options.max_depth;
    // Sebald Fig. 4: this device's key from its identifier and the seed.
    ctx["noise_key"] = generate_tea_key(zafar_tea_key(), make_uint2(options.device, options.seed));
}

struct SolidMaterials {
    std::shared_ptr<Material> floor, box, glass;
};

/// The tutorial's tiled floor, rusty box and glass crystal; their lengths placed.
SolidMaterials create_materials(Context& ctx, const Placement& placement) {
    auto phong = ctx.create_program(LUCENT_PROGRAM(fog::fog_phong));
    auto opaque = ctx.create_program(LUCENT_PROGRAM(fog::fog_opaque_shadow));
    SolidMaterials m{ctx.create_material(), ctx.create_material(), ctx.create_material()};
    m.floor->set_name("floor tiles");
    m.floor->set_closest_hit(fog::kRadianceRay, phong);
    m.floor->set_any_hit(fog::kShadowRay, opaque);
    (*m.floor)["Kd_a"] = make_float3(0.75f, 0.72f, 0.66f);
    (*m.floor)["Kd_b"] = make_float3(0.45f, 0.42f, 0.38f);
    (*m.floor)["Ks"] = make_float3(0.1f);
    (*m.floor)["phong_exponent"] = 40.0f;
    (*m.floor)["Kr"] = make_float3(0.1f);
    (*m.floor)["pattern"] = 0u;
    (*m.floor)["pattern_scale"] = placement.length(2.0f);
    m.box->set_name("rusty box");
    m.box->set_closest_hit(fog::kRadianceRay, phong);
    m.box->set_any_hit(fog::kShadowRay, opaque);
    (*m.box)["Kd_a"] = make_float3(0.55f, 0.56f, 0.6f);
    (*m.box)["Kd_b"] = make_float3(0.42f, 0.2f, 0.07f);
    (*m.box)["Ks"] = make_float3(0.5f);
    (*m.box)["phong_exponent"] = 60.0f;
    (*m.box)["Kr"] = make_float3(0.35f);
    (*m.box)["pattern"] = 1u;
    (*m.box)["pattern_scale"] = placement.length(1.2f);
    m.glass->set_name("crystal");
    m.glass->set_closest_hit(fog::kRadianceRay, ctx.create_program(LUCENT_PROGRAM(fog::fog_glass)));
    m.glass->set_any_hit(fog::kShadowRay,
                         ctx.create_program(LUCENT_PROGRAM(fog::fog_glass_shadow)));
    (*m.glass)["ior"] = 1.5f;
    (*m.glass)["extinction"] = make_float3(
        placement.per_length(0.35f), placement.per_length(0.06f), placement.per_length(0.22f));
    (*m.glass)["shadow_tint"] = make_float3(0.78f, 0.9f, 0.84f);
    return m;
}

/// The triangles in a GeometryGroup of their own: it gets the triangle BVH's fast
/// traversal, which a group holding the fog box (a custom primitive) would lose.
std::shared_ptr<GeometryGroup> solid_group(Context& ctx, const SolidMaterials& materials,
                                           const Placement& placement) {
    auto attributes = ctx.create_program(LUCENT_PROGRAM(fog::fog_mesh_attributes));
    auto solids = ctx.create_geometry_group();
    auto add_mesh = [&](const Mesh& mesh, const std::shared_ptr<Material>& material,
                        const char* name) {
        auto positions =
            ctx.create_buffer<float3>(BufferType::kInput, unsigned(mesh.positions.size()));
        positions->upload(mesh.positions);
        auto triangles =
            ctx.create_buffer<uint3>(BufferType::kInput, unsigned(mesh.triangles.size()));
        triangles->upload(mesh.triangles);
        auto geometry = ctx.create_geometry_triangles();
        geometry->set_name(name);
        geometry->set_vertices(positions);
        geometry->set_indices(triangles);
        geometry->set_attribute_program(attributes);
        (*geometry)["positions"] = positions;
        (*geometry)["triangles"] = triangles;
        auto instance = ctx.create_geometry_instance();
        instance->set_geometry(geometry);
        instance->add_material(material);
        solids->add_child(instance);
    };
    add_mesh(placed(floor_mesh(), placement), materials.floor, "floor");
    add_mesh(placed(box_mesh(make_float3(-5.0f, 0.0f, -3.5f), make_float3(-1.0f, 7.0f, 0.5f)),
                    placement),
             materials.box, "box");
    add_mesh(placed(crystal_mesh(make_float3(3.5f, 0.0f, 2.0f), 1.4f), placement),
             materials.glass, "crystal");
    return solids;
}

/// Sebald §3.1: a box with the floor's x, z extent and the fog's height, in a group of its
/// own beside the solids; both under the top object.
void add_fog_box(Context& ctx, const FogOptions& options, const Placement& placement,
                 const std::shared_ptr<GeometryGroup>& solids) {
    auto fog_material = ctx.create_material();
    fog_material->set_name("fog");
    fog_material->set_closest_hit(fog::kRadianceRay,
                                  ctx.create_program(LUCENT_PROGRAM(fog::fog_volume)));
    fog_material->set_any_hit(fog::kShadowRay,
                              ctx.create_program(LUCENT_PROGRAM(fog::fog_volume_shadow)));
    (*fog_material)["density"] = placement.per_length(options.density);
    (*fog_material)["step"] = placement.length(options.step);
    (*fog_material)["noise_scale"] = placement.length(options.noise_scale);
    (*fog_material)["noise"] = unsigned(options.noise);
    (*fog_material)["falloff"] = unsigned(options.falloff);
    (*fog_material)["rounds"] = options.rounds;
    (*fog_material)["fog_color"] = make_float3(0.62f, 0.66f, 0.72f);
    auto fog_box = ctx.create_geometry();
    fog_box->set_name("fog box");
    fog_box->set_primitive_count(1);
    fog_box->set_bounding_box_program(ctx.create_program(LUCENT_PROGRAM(fog::fog_box_bounds)));
    fog_box->set_intersection_program(ctx.create_program(LUCENT_PROGRAM(fog::fog_box_intersect)));
    auto instance = ctx.create_geometry_instance();
    instance->set_geometry(fog_box);
    // On the instance: its intersection and its closest hit both read them.
    (*instance)["box_min"] = placement.point(make_float3(-kFloorHalf, 0.0f, -kFloorHalf));
    (*instance)["box_max"] = placement.point(make_float3(kFloorHalf, options.height, kFloorHalf));
    instance->add_material(fog_material);
    auto fog_group = ctx.create_geometry_group();
    fog_group->add_child(instance);
    auto top = ctx.create_group();
    top->add_child(solids);
    top->add_child(fog_group);
    ctx["top_object"] = top;
    ctx["solid_object"] = solids;
}

/// The miss program: the equirectangular map `file` (.hdr or .exr), or the procedural sky
/// when it is empty.
std::shared_ptr<Program> environment_program(Context& ctx, const std::string& file) {
    auto miss = ctx.create_program(LUCENT_PROGRAM(fog::fog_environment));
    DiffuseTextures textures(ctx);  // a white texel stands in when there is no map
    if (file.empty()) {
        (*miss)["environment"] = textures("");
        (*miss)["has_environment"] = 0u;
        return miss;
    }
    const scene::TextureImage map = scene::load_linear_image(file);
    auto texels = ctx.create_buffer<float4>(BufferType::kInput, map.width, map.height);
    texels->upload(map.texels);
    auto sampler = ctx.create_texture_sampler();
    sampler->set_buffer(texels);
    sampler->set_wrap_mode(WrapMode::kRepeat, WrapMode::kClampToEdge);
    sampler->set_filter(FilterMode::kLinear);
    (*miss)["environment"] = sampler;
    (*miss)["has_environment"] = 1u;
    return miss;
}

}  // namespace

FogOptions read_fog_options(const OptionValues& v) {
    FogOptions o;
    o.fog = v.on("fog");
    o.step = v.number("step");
    o.height = v.number("height");
    o.density = v.number("density");
    o.noise_scale = v.number("noise_scale");
    o.noise = v.on("noise");
    o.falloff = v.on("falloff");
    o.rounds = unsigned(v.integer("rounds"));
    o.device = unsigned(v.integer("device"));
    o.seed = unsigned(v.integer("seed"));
    o.max_depth = unsigned(v.integer("max_depth"));
    o.environment = v.text("environment");
    o.orbit_degrees = v.number("orbit");
    o.eye_height = v.number("eye_height");
    o.eye_distance = v.number("eye_distance");
    return o;
}

struct FogScene::Impl {
    Context ctx;
    FogOptions options;
    Placement placement;
    unsigned width, height;
    std::shared_ptr<Buffer> camera, output;

    Impl(const FogOptions& o, const Placement& p, unsigned w, unsigned h, const ContextOptions& c)
        : ctx(c), options(o), placement(p), width(w), height(h) {}
};

FogScene::FogScene(const FogOptions& options, unsigned width, unsigned height,
                   const ContextOptions& context_options, const Placement& placement)
    : m(std::make_unique<Impl>(options, placement, width, height, context_options)) {
    Context& ctx = m->ctx;
    set_up_context(ctx, options, placement);
    const std::shared_ptr<GeometryGroup> solids =
        solid_group(ctx, create_materials(ctx, placement), placement);
    if (options.fog)
        add_fog_box(ctx, options, placement, solids);
    else
        ctx["top_object"] = solids;
    ctx.set_miss_program(fog::kRadianceRay, environment_program(ctx, options.environment));

    m->camera = ctx.create_buffer<sample_common::PinholeCamera>(BufferType::kInput, 1);
    m->output = ctx.create_buffer<float4>(BufferType::kOutput, width, height);
    auto camera = ctx.create_program(LUCENT_PROGRAM(fog::fog_camera));
    (*camera)["camera"] = m->camera;
    (*camera)["output"] = m->output;
    ctx.set_ray_generation_program(0, camera);
}

FogScene::~FogScene() = default;

scene::Camera FogScene::orbit_camera(float orbit_degrees) const {
    const float a = (orbit_degrees + kOrbitStartDegrees) * 3.14159265f / 180.0f;
    scene::Camera camera;
    const float r = m->options.eye_distance;
    camera.eye = make_float3(r * std::sin(a), m->options.eye_height, -r * std::cos(a));
    camera.look = kLookAt;
    camera.fov_degrees = 45.0f;
    return m->placement.camera(camera);
}

const LaunchReport& FogScene::render(float orbit_degrees) {
    return render(orbit_camera(orbit_degrees));
}

const LaunchReport& FogScene::render(const scene::Camera& camera) {
    // The camera is data in a buffer: moving it re-uploads 48 bytes, it recompiles nothing.
    m->camera->upload(std::vector<sample_common::PinholeCamera>{
        pinhole_camera(camera, float(m->width) / float(m->height))});
    m->ctx.launch(0, m->width, m->height);
    return m->ctx.last_launch();
}

Context& FogScene::context() {
    return m->ctx;
}
const Buffer& FogScene::output() const {
    return *m->output;
}

}  // namespace lucent::samples

#include "samples/hair/hair_scene.h"

#include <algorithm>
#include <cmath>

#include "samples/hair/hair_programs.h"
#include "samples/scene_setup.h"

namespace lucent::samples {

namespace {

/// A latitude-longitude sphere of `rings` x `sectors` quads, wound outwards, its vertices on
/// the sphere (its faces a little inside: 0.2 % of the radius at 48 x 24).
scene::Mesh lat_long_sphere(float3 center, float radius, unsigned rings, unsigned sectors,
                            unsigned material) {
    scene::Mesh mesh;
    mesh.name = "head";
    for (unsigned i = 0; i <= rings; ++i) {
        const float theta = 3.14159265f * float(i) / float(rings);  // from the top
        for (unsigned j = 0; j <= sectors; ++j) {
            const float phi = 6.2831853f * float(j) / float(sectors);
            mesh.positions.push_back(
                center + radius * make_float3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                              std::sin(theta) * std::sin(phi)));
            mesh.uvs.push_back(make_float2(float(j) / float(sectors), float(i) / float(rings)));
        }
    }
    const unsigned row = sectors + 1;
    for (unsigned i = 0; i < rings; ++i)
        for (unsigned j = 0; j < sectors; ++j) {
            const unsigned a = i * row + j, b = a + row, c = b + 1, d = a + 1;
            // Counter-clockwise seen from outside: the normal cross(b - a, d - a) points out.
            if (i > 0) mesh.indices.push_back(uint3{a, d, b});
            if (i + 1 < rings) mesh.indices.push_back(uint3{d, c, b});
        }
    mesh.materials.assign(mesh.indices.size(), material);
    return mesh;
}

/// A parallelogram corner + s edge1 + t edge2 as two triangles facing cross(edge1, edge2).
scene::Mesh quad(const char* name, float3 corner, float3 edge1, float3 edge2, unsigned material) {
    scene::Mesh mesh;
    mesh.name = name;
    mesh.positions = {corner, corner + edge1, corner + edge1 + edge2, corner + edge2};
    mesh.indices = {uint3{0, 1, 2}, uint3{0, 2, 3}};
    mesh.materials.assign(2, material);
    return mesh;
}

scene::Material material(const char* name, scene::MaterialKind kind, float3 diffuse,
                         float3 specular, float roughness) {
    scene::Material m{name, diffuse};
    m.kind = kind;
    m.specular = specular;
    m.roughness = roughness;
    return m;
}

/// One GeometryGroup over one instance, with a visibility mask.
std::shared_ptr<GeometryGroup> masked_group(Context& ctx,
                                            const std::shared_ptr<GeometryInstance>& instance,
                                            unsigned mask) {
    auto group = ctx.create_geometry_group();
    group->add_child(instance);
    group->set_visibility_mask(mask);
    return group;
}

template <class T>
std::shared_ptr<Buffer> input(Context& ctx, const std::vector<T>& data) {
    auto buffer = ctx.create_buffer<T>(BufferType::kInput, unsigned(data.size()));
    buffer->upload(data);
    return buffer;
}

}  // namespace

HairSceneData make_hair_scene(const HairShape& shape) {
    using scene::MaterialKind;
    HairSceneData data;
    data.head_center = make_float3(0.0f, 0.0f, 0.0f);
    data.head_radius = 1.0f;
    scene::Scene& s = data.meshes;
    s.name = "hair";
    s.materials = {
        material("ground", MaterialKind::kLambert, {0.5f, 0.5f, 0.5f}, {0, 0, 0}, 1.0f),
        material("head", MaterialKind::kLambert, {0.75f, 0.52f, 0.42f}, {0, 0, 0}, 1.0f),
        material("key light", MaterialKind::kLambert, {0, 0, 0}, {0, 0, 0}, 1.0f),
    };
    s.materials[2].emission = make_float3(30.0f, 28.0f, 25.0f);
    const float ground = data.head_center.y - data.head_radius;
    s.meshes.push_back(quad("ground", make_float3(-10.0f, ground, 10.0f),
                            make_float3(20.0f, 0.0f, 0.0f), make_float3(0.0f, 0.0f, -20.0f), 0));
    s.meshes.push_back(lat_long_sphere(data.head_center, data.head_radius, 24, 48, 1));
    // The key light: a 1.6 x 1.6 square above, left and in front of the head, facing down,
    // declared (for next-event estimation) and as geometry (for the rays that hit it).
    scene::AreaLight key{make_float3(-2.8f, 4.5f, 1.2f), make_float3(1.6f, 0.0f, 0.0f),
                         make_float3(0.0f, 0.0f, 1.6f), s.materials[2].emission};
    s.area_lights.push_back(key);
    s.meshes.push_back(quad("key light", key.corner, key.edge1, key.edge2, 2));
    s.point_lights.push_back({make_float3(4.0f, 2.5f, 5.0f), make_float3(28.0f, 32.0f, 38.0f)});
    s.camera.eye = make_float3(0.0f, 1.3f, 6.8f);
    s.camera.look = make_float3(0.0f, -0.25f, 0.0f);
    s.camera.up = make_float3(0.0f, 1.0f, 0.0f);
    s.camera.fov_degrees = 36.0f;

    data.spheres = {
        {make_float3(1.9f, ground + 0.5f, 1.0f), 0.5f,
         material("gold", MaterialKind::kMetal, {0, 0, 0}, {1.0f, 0.78f, 0.34f}, 0.25f)},
        {make_float3(-2.0f, ground + 0.55f, 1.3f), 0.55f,
         material("glass", MaterialKind::kDielectric, {0, 0, 0}, {0, 0, 0}, 0.0f)},
        {make_float3(0.7f, ground + 0.35f, 2.1f), 0.35f,
         material("blue coated", MaterialKind::kCoated, {0.08f, 0.18f, 0.6f}, {0, 0, 0}, 0.1f)},
    };

    scene::HairStyle style;
    style.segments = shape.strands * scene::kHairSegmentsPerStrand;
    style.type = shape.type;
    style.center = data.head_center;
    style.head_radius = data.head_radius;
    if (shape.strands > 0) data.hair = scene::make_hair_strands(style);
    data.hair_type = shape.type;
    // Auburn: a pigmented base (eumelanin and pheomelanin absorb blue most) under a cuticle
    // coat of keratin's index, 1.55 (Marschner et al. 2003).
    data.hair_material =
        material("hair", MaterialKind::kCoated, {0.42f, 0.17f, 0.06f}, {0, 0, 0}, 0.35f);
    data.hair_material.ior = 1.55f;
    return data;
}

std::vector<unsigned> light_masks(const scene::Scene& scene, bool light_linking) {
    const size_t lights = area_lights(scene).size() + scene.point_lights.size();
    std::vector<unsigned> masks(lights, kVisibilityMaskAll);
    if (light_linking && !masks.empty()) masks[0] = hair_sample::kSceneMask;
    return masks;
}

HairGraph build_hair_graph(Context& ctx, const HairSceneData& data, bool light_linking) {
    HairGraph out;
    out.scene_size = scene_size(data.meshes);
    bind_lights(ctx, data.meshes);
    ctx["scene_size"] = out.scene_size;
    out.light_masks = input(ctx, light_masks(data.meshes, light_linking));
    ctx["light_masks"] = out.light_masks;

    DiffuseTextures texture_for(ctx);
    auto make_material = [&](const scene::Material& m, const std::shared_ptr<Program>& hit) {
        auto material = ctx.create_material();
        material->set_name(m.name);
        material->set_closest_hit(pathtracer::kRadianceRay, hit);
        (*material)["Kd"] = m.diffuse;
        (*material)["Ks"] = m.specular;
        (*material)["Ke"] = m.emission;
        (*material)["diffuse_map"] = texture_for("");  // a white texel: no textures here
        (*material)["specular_map"] = texture_for("");
        // As the path tracer does: GGX alpha = roughness², floored to stay finite in float.
        (*material)["alpha"] = std::max(m.roughness * m.roughness, 1e-3f);
        (*material)["ior"] = m.ior;
        out.materials.push_back(material);
        return material;
    };

    // The meshes: every material is Lambert (the emitter too, with its Ke).
    auto mesh_hit = ctx.create_program(LUCENT_PROGRAM(hair_sample::linked_mesh_lambert));
    std::vector<std::shared_ptr<Material>> mesh_materials;
    for (const scene::Material& m : data.meshes.materials)
        mesh_materials.push_back(make_material(m, mesh_hit));
    auto attributes = ctx.create_program(LUCENT_PROGRAM(sample_common::mesh_normal_uv));
    std::shared_ptr<Node> meshes = mesh_group(ctx, data.meshes, attributes, mesh_materials);
    meshes->set_visibility_mask(hair_sample::kSceneMask);

    // The spheres: one material each, by its kind.
    auto spheres = ctx.create_geometry_spheres();
    std::vector<float3> centers;
    std::vector<float> radii;
    std::vector<unsigned> sphere_materials;
    auto sphere_instance = ctx.create_geometry_instance();
    for (const HairSceneSphere& sphere : data.spheres) {
        centers.push_back(sphere.center);
        radii.push_back(sphere.radius);
        sphere_materials.push_back(unsigned(sphere_materials.size()));
        const auto kind = sphere.material.kind;
        auto hit = ctx.create_program(kind == scene::MaterialKind::kMetal
                                          ? LUCENT_PROGRAM(hair_sample::linked_sphere_metal)
                                      : kind == scene::MaterialKind::kDielectric
                                          ? LUCENT_PROGRAM(hair_sample::linked_sphere_glass)
                                          : LUCENT_PROGRAM(hair_sample::linked_sphere_coated));
        sphere_instance->add_material(make_material(sphere.material, hit));
    }
    spheres->set_centers(input(ctx, centers));
    spheres->set_radii(input(ctx, radii));
    spheres->set_material_indices(input(ctx, sphere_materials));
    sphere_instance->set_geometry(spheres);

    auto top = ctx.create_group();
    top->add_child(meshes);
    top->add_child(masked_group(ctx, sphere_instance, hair_sample::kSceneMask));
    if (!data.hair.segments.empty()) {
        auto curves = ctx.create_geometry_curves();
        curves->set_name("hair");
        curves->set_curve_type(data.hair_type);
        curves->set_vertices(input(ctx, data.hair.vertices));
        curves->set_radii(input(ctx, data.hair.radii));
        curves->set_segment_indices(input(ctx, data.hair.segments));
        auto hair_instance = ctx.create_geometry_instance();
        hair_instance->set_geometry(curves);
        hair_instance->add_material(
            make_material(data.hair_material,
                          ctx.create_program(LUCENT_PROGRAM(hair_sample::linked_curve_coated))));
        top->add_child(masked_group(ctx, hair_instance, hair_sample::kHairMask));
    }
    ctx["top_object"] = top;
    out.top = top;
    return out;
}

}  // namespace lucent::samples

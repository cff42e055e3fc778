#include "samples/scene_setup.h"

#include "samples/settings_error.h"
#include "scene/texture_image.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace lucent::samples {

scene::Scene load_render_scene(const RenderSettings& settings) {
    scene::Scene scene = scene::load_scene(settings.scene.empty() ? "cornell" : settings.scene,
                                             settings.on_load_progress);
    if (settings.scene_camera) {
        const unsigned n = *settings.scene_camera;
        const size_t count = scene.cameras.size();
        if (n >= count)
            throw SettingsError("--camera " + std::to_string(n) + ": scene '" + scene.name +
                                "' has " + std::to_string(count) +
                                (count == 1 ? " camera of its own" : " cameras of its own") +
                                (count == 0 ? "" : " (0 to " + std::to_string(count - 1) + ")"));
        if (!scene.cameras[n].unusable.empty())
            throw SettingsError("--camera " + std::to_string(n) + ": " + scene.cameras[n].unusable);
        scene.camera = scene.cameras[n];
    }
    if (!settings.camera.empty()) {
        scene.camera = settings.camera.applied_to(scene.camera);
        return scene;
    }
    // The scene's own camera is checked as the flags are: a file's camera that cannot see
    // (a glTF node's singular matrix, a JSON up along the view) is an error, not a black image.
    try {
        scene.camera = CameraOverride{}.applied_to(scene.camera);
    } catch (const SettingsError& e) {
        throw SettingsError("scene '" + scene.name + "': its " + e.what() +
                            "; fix the scene's camera, or replace it with --eye --look --up --fov");
    }
    return scene;
}

float scene_size(const scene::Scene& scene) {
    // The world-space box: an instance's transform moves and scales its mesh.
    bool any = false;
    for (const scene::Instance& i : scene::drawn_instances(scene))
        any = any || !scene.meshes[i.mesh].positions.empty();
    if (!any) return 0;
    const scene::Bounds b = scene::scene_bounds(scene);
    return max_component(b.hi - b.lo);
}

std::string scene_note(const scene::Scene& scene) {
    std::string note = scene.name + ", " + std::to_string(scene.triangle_count()) + " triangles";
    if (!scene.instances.empty())
        note += " stored, " + std::to_string(scene.drawn_triangle_count()) + " drawn by " +
                std::to_string(scene.instances.size()) + " instances";
    return note;
}

MeshBuffers upload_mesh(Context& ctx, const scene::Mesh& mesh) {
    MeshBuffers b;
    b.positions = ctx.create_buffer<float3>(BufferType::kInput, unsigned(mesh.positions.size()));
    b.positions->upload(mesh.positions);
    b.triangles = ctx.create_buffer<uint3>(BufferType::kInput, unsigned(mesh.indices.size()));
    b.triangles->upload(mesh.indices);
    b.materials = ctx.create_buffer<unsigned>(BufferType::kInput, unsigned(mesh.materials.size()));
    b.materials->upload(mesh.materials);
    b.uvs = ctx.create_buffer<float2>(BufferType::kInput, unsigned(mesh.uvs.size()));
    if (!mesh.uvs.empty()) b.uvs->upload(mesh.uvs);
    return b;
}

std::shared_ptr<Node> place_meshes(Context& ctx, const scene::Scene& scene,
                                   const std::vector<std::shared_ptr<GeometryInstance>>& per_mesh) {
    if (scene.instances.empty()) {
        auto group = ctx.create_geometry_group();
        for (const auto& instance : per_mesh)
            if (instance) group->add_child(instance);
        return group;
    }
    std::vector<std::shared_ptr<GeometryGroup>> groups(per_mesh.size());
    auto top = ctx.create_group();
    for (const scene::Instance& placed : scene.instances) {
        if (placed.mesh >= per_mesh.size())
            throw Error("place_meshes: instance of mesh " + std::to_string(placed.mesh) +
                        " in a scene of " + std::to_string(per_mesh.size()) + " meshes");
        if (!per_mesh[placed.mesh]) continue;
        auto& group = groups[placed.mesh];
        if (!group) {  // the first instance of this mesh: its GeometryGroup, shared by the rest
            group = ctx.create_geometry_group();
            group->add_child(per_mesh[placed.mesh]);
        }
        auto transform = ctx.create_transform();
        transform->set_matrix(placed.transform);
        transform->set_child(group);
        top->add_child(transform);
    }
    return top;
}

std::shared_ptr<Node> mesh_group(
    Context& ctx, const scene::Scene& scene, const std::shared_ptr<Program>& attributes,
    const std::vector<std::shared_ptr<Material>>& materials,
    const std::function<void(const scene::Mesh&, const MeshBuffers&)>& each) {
    std::vector<std::shared_ptr<GeometryInstance>> instances;
    unsigned index = 0;
    for (const auto& mesh : scene.meshes) {
        const MeshBuffers buffers = upload_mesh(ctx, mesh);
        auto triangles = ctx.create_geometry_triangles();
        triangles->set_name(mesh.name);
        triangles->set_vertices(buffers.positions);
        triangles->set_indices(buffers.triangles);
        triangles->set_material_indices(buffers.materials);
        triangles->set_attribute_program(attributes);
        (*triangles)["positions"] = buffers.positions;
        (*triangles)["triangles"] = buffers.triangles;
        (*triangles)["uvs"] = buffers.uvs;
        auto instance = ctx.create_geometry_instance();
        instance->set_geometry(triangles);
        (*instance)["gbuffer_instance"] = index++;  // the G-buffer's instance AOV
        for (const auto& material : materials) instance->add_material(material);
        instances.push_back(instance);
        if (each) each(mesh, buffers);
    }
    return place_meshes(ctx, scene, instances);
}

sample_common::PinholeCamera pinhole_camera(const scene::Camera& c, float aspect) {
    const float3 W = normalize(c.look - c.eye), U = normalize(cross(W, c.up)), V = cross(U, W);
    const float half_height = std::tan(c.fov_degrees * 0.5f * 3.14159265f / 180.0f);
    return {c.eye, U * (half_height * aspect), V * half_height, W};
}

std::vector<sample_common::AreaLight> area_lights(const scene::Scene& scene) {
    std::vector<sample_common::AreaLight> areas;
    for (const auto& l : scene::emitter_lights(scene))
        areas.push_back({l.corner, l.edge1, l.edge2, l.emission, l.triangle ? 1u : 0u});
    return areas;
}

float light_power(const sample_common::AreaLight& light) {
    const float3 e = light.emission;
    return 3.14159265f * sample_common::light_area(light) * std::max(0.0f, e.x + e.y + e.z);
}

std::vector<float> light_cdf(const std::vector<sample_common::AreaLight>& lights) {
    std::vector<double> power;
    double total = 0;
    for (const auto& l : lights) total += power.emplace_back(light_power(l));
    std::vector<float> cdf;
    double sum = 0;
    for (size_t i = 0; i < lights.size(); ++i) {
        sum += total > 0 ? power[i] / total : 1.0 / double(lights.size());
        cdf.push_back(float(sum));
    }
    if (!cdf.empty()) cdf.back() = 1.0f;  // whatever the rounding, pick_light picks one
    return cdf;
}

bool report_if_unlit(const scene::Scene& scene, const std::string& sample,
                     const std::string& fallback) {
    if (scene::has_lights(scene)) return true;
    std::fprintf(stderr,
                 "%s: scene '%s' has no light (no point or area light, no emissive material); "
                 "%s\n",
                 sample.c_str(), scene.name.c_str(), fallback.c_str());
    return false;
}

void bind_lights(Context& ctx, const scene::Scene& scene) {
    std::vector<sample_common::PointLight> points;
    for (const auto& l : scene.point_lights) points.push_back({l.position, l.intensity});
    const std::vector<sample_common::AreaLight> areas = area_lights(scene);
    auto point_buffer =
        ctx.create_buffer<sample_common::PointLight>(BufferType::kInput, unsigned(points.size()));
    point_buffer->upload(points);
    auto area_buffer =
        ctx.create_buffer<sample_common::AreaLight>(BufferType::kInput, unsigned(areas.size()));
    area_buffer->upload(areas);
    const std::vector<float> cdf = light_cdf(areas);
    auto cdf_buffer = ctx.create_buffer<float>(BufferType::kInput, unsigned(cdf.size()));
    cdf_buffer->upload(cdf);
    ctx["point_lights"] = point_buffer;
    ctx["area_lights"] = area_buffer;
    ctx["area_light_cdf"] = cdf_buffer;
}

scene::Image image_from_output(const Buffer& output, unsigned layer) {
    scene::Image image;
    image.width = output.size().x;
    image.height = output.size().y;
    if (layer >= std::max(1u, output.size().z))
        throw Error("image_from_output: layer " + std::to_string(layer) + " of a buffer of " +
                    std::to_string(output.size().z) + " layers");
    const size_t count = size_t(image.width) * image.height;
    const float4* pixels = output.data<float4>() + count * layer;
    image.pixels.resize(count);
    for (size_t i = 0; i < count; ++i) image.pixels[i] = make_float3(pixels[i]);
    return image;
}

std::shared_ptr<TextureSampler> DiffuseTextures::operator()(const std::string& file) {
    auto& sampler = m_samplers[file];
    if (sampler) return sampler;
    scene::TextureImage loaded;
    const scene::TextureImage* carried = nullptr;
    if (m_scene) {
        auto it = m_scene->textures.find(file);
        if (it != m_scene->textures.end()) carried = &it->second;
    }
    if (!carried)
        loaded = file.empty() ? scene::TextureImage{1, 1, {make_float4(1, 1, 1, 1)}}
                              : scene::load_texture(file);
    const scene::TextureImage& image = carried ? *carried : loaded;
    auto texels = m_ctx.create_buffer<float4>(BufferType::kInput, image.width, image.height);
    texels->upload(image.texels);
    sampler = m_ctx.create_texture_sampler();
    sampler->set_buffer(texels);
    sampler->set_wrap_mode(WrapMode::kRepeat, WrapMode::kRepeat);
    sampler->set_filter(FilterMode::kLinear);
    return sampler;
}

}  // namespace lucent::samples

// Host-side steps the samples that render a scene/ Scene share: its size, its meshes as
// buffers, the pinhole camera frame, and the output buffer as an image.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "lucent/context.h"
#include "scene/image_io.h"
#include "scene/scene.h"

namespace lucent::samples {

/// The largest coordinate magnitude of any vertex: offsets for secondary rays scale with
/// it (the Cornell box is in millimetres).
float scene_extent(const scene::Scene& scene);

/// A mesh's arrays as input buffers (uvs may be an empty buffer).
struct MeshBuffers {
    std::shared_ptr<Buffer> positions, triangles, materials, uvs;
};
MeshBuffers upload_mesh(Context& ctx, const scene::Mesh& mesh);

/// One GeometryTriangles per mesh of `scene`, each in an instance with all of `materials` (a
/// triangle's material index picks one), under a new GeometryGroup. Each geometry gets the
/// attribute program and the variables attribute programs read: "positions", "triangles"
/// and "uvs" (empty when the mesh has none). `each`, when given, sees every mesh with its
/// buffers, for graphs built beside this one (IGI's boxes).
std::shared_ptr<GeometryGroup> mesh_group(
    Context& ctx, const scene::Scene& scene, const std::shared_ptr<Program>& attributes,
    const std::vector<std::shared_ptr<Material>>& materials,
    const std::function<void(const scene::Mesh&, const MeshBuffers&)>& each = {});

/// The scene's lights as the input buffers "point_lights" and "area_lights" on the context,
/// in the program module's own layouts {position, intensity} and {corner, edge1, edge2,
/// emission} (the direct and path tracer samples).
template <class PointLight, class AreaLight>
void bind_lights(Context& ctx, const scene::Scene& scene) {
    std::vector<PointLight> points;
    for (const auto& l : scene.point_lights) points.push_back({l.position, l.intensity});
    std::vector<AreaLight> areas;
    for (const auto& l : scene.area_lights) areas.push_back({l.corner, l.edge1, l.edge2, l.emission});
    auto point_buffer = ctx.create_buffer<PointLight>(BufferType::kInput, unsigned(points.size()));
    point_buffer->upload(points);
    auto area_buffer = ctx.create_buffer<AreaLight>(BufferType::kInput, unsigned(areas.size()));
    area_buffer->upload(areas);
    ctx["point_lights"] = point_buffer;
    ctx["area_lights"] = area_buffer;
}

/// Pinhole camera: W to the image centre, U and V half the image's width and height.
struct PinholeFrame {
    float3 U, V, W;
};
PinholeFrame pinhole_frame(const scene::Camera& camera, float aspect);

/// The float4 output buffer of a launch as a linear RGB image: its layer `layer` (z) when it
/// has several.
scene::Image image_from_output(const Buffer& output, unsigned layer = 0);

/// Diffuse maps as texture samplers (bilinear, repeating), each file loaded once; a
/// material without one ("") gets a 1x1 white texel, so programs always sample a texture.
class DiffuseTextures {
  public:
    explicit DiffuseTextures(Context& ctx) : m_ctx(ctx) {}
    std::shared_ptr<TextureSampler> operator()(const std::string& file);

  private:
    Context& m_ctx;
    std::map<std::string, std::shared_ptr<TextureSampler>> m_samplers;
};

}  // namespace lucent::samples

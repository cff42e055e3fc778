// Host-side steps the samples that render a scene/ Scene share: its size, its meshes as
// buffers, its lights, the pinhole camera, and the output buffer as an image.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "lucent/context.h"
#include "samples/common/camera.h"
#include "samples/common/lights.h"
#include "samples/sample.h"
#include "scene/image_io.h"
#include "scene/scene.h"

namespace lucent::samples {

/// The scene of settings.scene (default: the Cornell box), its camera settings.scene_camera
/// of the file's own when given (SettingsError naming how many it has when out of range),
/// with the parts of it that settings.camera gives replaced (SettingsError for a camera
/// that cannot see).
scene::Scene load_render_scene(const RenderSettings& settings);

/// The longest side of the box of every vertex the scene draws (world space; 0 without any):
/// what distances that depend on the scene's size are fractions of (the Cornell box is in
/// millimetres), and what sample_common::offset_ray_origin's offset near 0 follows. Not
/// where the scene is: a box moved to 1e6 has the size it had at 0.
float scene_size(const scene::Scene& scene);

/// The scene's name and size for a stage's note: "cornell, 32 triangles", or with instances
/// "spheres, 4098 triangles stored, 4096002 drawn by 1001 instances".
std::string scene_note(const scene::Scene& scene);

/// A mesh's arrays as input buffers (uvs may be an empty buffer).
struct MeshBuffers {
    std::shared_ptr<Buffer> positions, triangles, materials, uvs;
};
MeshBuffers upload_mesh(Context& ctx, const scene::Mesh& mesh);

/// One GeometryTriangles per mesh of `scene`, each in an instance with all of `materials` (a
/// triangle's material index picks one), placed by place_meshes. Each geometry gets the
/// attribute program and the variables attribute programs read: "positions", "triangles"
/// and "uvs" (empty when the mesh has none); their data stay in object space, the hit
/// programs take normals to the world (lucent::object_to_world_normal). Each instance gets
/// "gbuffer_instance", the mesh's index (samples/common/gbuffer_programs.h). `each`, when
/// given, sees every mesh with its buffers, for graphs built beside this one (IGI's boxes).
std::shared_ptr<Node> mesh_group(
    Context& ctx, const scene::Scene& scene, const std::shared_ptr<Program>& attributes,
    const std::vector<std::shared_ptr<Material>>& materials,
    const std::function<void(const scene::Mesh&, const MeshBuffers&)>& each = {});

/// One GeometryInstance per mesh of `scene` (null for a mesh to leave out) as the scene
/// draws them. Without Scene::instances: every instance under one GeometryGroup, as the
/// scene's meshes were always built. With them: a GeometryGroup per mesh, built once, and
/// a Group over one Transform per instance, each pointing at its mesh's GeometryGroup, so a
/// mesh drawn a thousand times has one BVH (and one copy of its buffers) and the Group's
/// BVH has a thousand boxes.
std::shared_ptr<Node> place_meshes(Context& ctx, const scene::Scene& scene,
                                   const std::vector<std::shared_ptr<GeometryInstance>>& per_mesh);

/// The scene's lights as the input buffers "point_lights", "area_lights" and
/// "area_light_cdf" (light_cdf of them) on the context, in the layouts of
/// samples/common/lights.h (the direct and path tracer samples).
void bind_lights(Context& ctx, const scene::Scene& scene);

/// The scene's area lights in the layout of samples/common/lights.h: its declared ones and
/// its emissive triangles (scene::emitter_lights).
std::vector<sample_common::AreaLight> area_lights(const scene::Scene& scene);

/// A light's power, pi A L summed over the colour channels (a Lambertian emitter's flux).
float light_power(const sample_common::AreaLight& light);

/// The cumulative distribution of choosing each light in proportion to its power (the last
/// entry 1; empty without lights; uniform when none has power), for sample_common::pick_light.
std::vector<float> light_cdf(const std::vector<sample_common::AreaLight>& lights);

/// When the scene has no light at all (scene::has_lights), one line on stderr naming the
/// sample, the scene and what the sample does instead (`fallback`); returns whether it has.
bool report_if_unlit(const scene::Scene& scene, const std::string& sample,
                     const std::string& fallback);

/// The pinhole camera of a scene::Camera for an image of this aspect (width / height): W
/// the unit view direction, U and V half the image's width and height at distance 1.
sample_common::PinholeCamera pinhole_camera(const scene::Camera& camera, float aspect);

/// The float4 output buffer of a launch as a linear RGB image: its layer `layer` (z) when it
/// has several.
scene::Image image_from_output(const Buffer& output, unsigned layer = 0);

/// Diffuse maps as texture samplers (bilinear, repeating), each file loaded once; a
/// material without one ("") gets a 1x1 white texel, so programs always sample a texture.
/// Given a scene, a name that is a key of its Scene::textures (a glTF image) is that image.
class DiffuseTextures {
  public:
    explicit DiffuseTextures(Context& ctx, const scene::Scene* scene = nullptr)
        : m_ctx(ctx), m_scene(scene) {}
    std::shared_ptr<TextureSampler> operator()(const std::string& file);

  private:
    Context& m_ctx;
    const scene::Scene* m_scene;
    std::map<std::string, std::shared_ptr<TextureSampler>> m_samplers;
};

}  // namespace lucent::samples

// A renderable scene as the samples consume it: triangle meshes with per-triangle
// materials, instances placing them (a mesh drawn several times is stored once), point and
// area lights, and cameras. Built in (`cornell`), or loaded from an OBJ + MTL file, a JSON
// scene description or a glTF 2.0 file.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "lucent/device/types.h"
#include "lucent/device/vector_math.h"
#include "scene/load_progress.h"
#include "scene/texture_image.h"

namespace lucent::scene {

/// How a physically based renderer (the path tracer) reads a Material; the other samples
/// read its Phong fields only.
enum class MaterialKind {
    kLambert,     // diffuse reflectance `diffuse`
    kMetal,       // GGX microfacet conductor, Schlick Fresnel with `specular` as its colour
                  // (`diffuse` when `specular` is black: a glTF metal's base colour)
    kDielectric,  // smooth glass of index `ior`
    kCoated,      // a clear GGX coat of index `ior` and `roughness` over a Lambert `diffuse`
};

/// Phong-style material of OBJ's MTL: diffuse reflectance (rho), specular reflectance and
/// exponent, emission, and an optional diffuse texture file (sRGB, linearised on load); and
/// for physically based renderers a kind with its roughness and index of refraction.
struct Material {
    std::string name;
    float3 diffuse{0.8f, 0.8f, 0.8f};
    float3 specular{0, 0, 0};
    float shininess = 0;
    float3 emission{0, 0, 0};
    std::string diffuse_texture;  // a file path, resolved against the file that named it,
                                  // or a key of Scene::textures (an image the scene carries)
    MaterialKind kind = MaterialKind::kLambert;
    float roughness = 0.3f;  // perceptual, in [0, 1]: GGX alpha = roughness^2
    float ior = 1.5f;        // of glass and of the coat, > 1
};

struct Mesh {
    std::string name;
    std::vector<float3> positions;
    std::vector<float3> normals;      // per vertex, empty when the file has none
    std::vector<float2> uvs;          // per vertex, empty when the file has none
    std::vector<uint3> indices;       // triangles
    std::vector<unsigned> materials;  // per triangle, index into Scene::materials
};

/// One placement of a mesh: its vertices are in the mesh's own (object) space, drawn at
/// transform * p in the world. Several instances of one mesh share its vertex data and, in
/// the node graph, its GeometryGroup and BVH (samples/scene_setup.h).
struct Instance {
    unsigned mesh = 0;      // index into Scene::meshes
    Matrix4x3 transform{};  // object to world, affine, row-major (lucent/device/types.h)
};

/// The identity transform.
Matrix4x3 identity_matrix();
/// a * b: b applied first.
Matrix4x3 multiply(const Matrix4x3& a, const Matrix4x3& b);
/// The inverse of an affine matrix; false (and `out` untouched) when it is singular.
bool invert(const Matrix4x3& m, Matrix4x3& out);

struct PointLight {
    float3 position;
    float3 intensity;  // radiant intensity per colour channel
};

/// An emitting parallelogram: corner + s * edge1 + t * edge2 for s, t in [0, 1]; or, when
/// `triangle`, the triangle of s, t >= 0, s + t <= 1 (an emissive mesh triangle). It emits on
/// one side, the one cross(edge1, edge2) points to (as a ceiling light emits downwards).
struct AreaLight {
    float3 corner, edge1, edge2;
    float3 emission;  // radiance
    bool triangle = false;
};

struct Camera {
    float3 eye{0, 0, 1}, look{0, 0, 0}, up{0, 1, 0};
    float fov_degrees = 45;  // vertical
    /// Why this camera of a file cannot be used (an orthographic glTF camera, one no node
    /// places); empty when it can. Choosing it (`render --camera N`) is then an error.
    std::string unusable{};
};

struct Scene {
    std::string name;
    std::vector<Mesh> meshes;
    /// Where the meshes are drawn. Empty: each mesh once, untransformed (OBJ, PLY, the
    /// built-in scenes, JSON without "instances"); otherwise only these are drawn.
    std::vector<Instance> instances;
    std::vector<Material> materials;
    std::vector<PointLight> point_lights;  // in world space, as all lights
    std::vector<AreaLight> area_lights;
    Camera camera;  // the default: a file's first camera, or one framing the scene
    /// The file's own cameras in its order (glTF's "cameras"), for `render --camera N`;
    /// empty for formats with at most one camera.
    std::vector<Camera> cameras;
    /// Images the scene carries rather than names as files (glTF's, embedded or decoded
    /// from its files), by the key a Material's diffuse_texture gives; linear RGBA.
    std::map<std::string, TextureImage> textures;

    /// Triangles stored (each mesh once, however many instances draw it).
    size_t triangle_count() const;
    /// Triangles drawn: each mesh's count times its instances.
    size_t drawn_triangle_count() const;
};

/// The instances the scene draws: Scene::instances, or one identity instance per mesh when
/// it has none. What everything that reads world-space geometry iterates.
std::vector<Instance> drawn_instances(const Scene& scene);

/// Appends a mesh that is drawn once, untransformed (an identity instance is added when the
/// scene has instances, so the mesh is not left out); returns its index.
unsigned add_untransformed_mesh(Scene& scene, Mesh mesh);

/// The smallest box holding every vertex the scene draws, in world space.
struct Bounds {
    float3 lo, hi;
};
Bounds scene_bounds(const Scene& scene);

/// A camera on +z of the scene's bounds, looking at their centre, that frames them (what a
/// scene without a camera of its own gets: an OBJ, or a JSON file without "camera").
Camera framing_camera(const Scene& scene);

/// True when the camera's up is zero or within about 0.06 degrees of its view direction
/// (eye to look, which must differ): the image's orientation is then left to rounding, and
/// the renders were only background.
bool up_along_view(const Camera& camera);

/// Every area light of the scene: its declared ones, then each triangle whose material
/// emits (Ke in MTL, "emission" in JSON) as a triangle light, unless it lies on a declared
/// light (the built-in Cornell box's light is both a declared light and its geometry).
std::vector<AreaLight> emitter_lights(const Scene& scene);

/// True when an emitting triangle of the scene lies on `light` (within `tolerance` of its
/// plane): the light is then geometry that rays can hit.
bool has_emitting_geometry(const Scene& scene, const AreaLight& light, float tolerance);

/// True when the scene has a light: a point light, an area light or an emitting triangle.
bool has_lights(const Scene& scene);

/// The names load_scene accepts without a file.
std::vector<std::string> builtin_scene_names();

/// A built-in scene by name, or a file: .obj (with its .mtl), .ply, .json, .gltf or .glb.
/// Throws lucent::Error naming the file (and line, or JSON location) and the fix for
/// anything malformed. `progress` hears of the bytes read of large OBJ, PLY and JSON-named
/// mesh files (docs/scenes.md gives the rates).
Scene load_scene(const std::string& name_or_path, const LoadProgress& progress = {});

/// The Cornell box with its two blocks (Goral et al. 1984, measured data of the Cornell
/// Program of Computer Graphics), in millimetres; lit by its ceiling light as an area light,
/// or by a point light of the same power hanging 10 cm below it.
Scene cornell_box(bool area_light);

/// The area-lit Cornell box with a rough metal tall block, a glass short block and a coated
/// (clear varnish over white) floor: every MaterialKind in one built-in scene.
Scene cornell_materials_box();

/// OBJ + MTL through tinyobjloader (polygons fanned into triangles).
Scene load_obj_scene(const std::string& path, const LoadProgress& progress = {});

/// A PLY mesh (ASCII or binary): positions, optional normals and uvs, faces fanned into
/// triangles, all with material 0.
Mesh load_ply_mesh(const std::string& path, const LoadProgress& progress = {});

/// A JSON scene description; see docs/scenes.md.
Scene load_json_scene(const std::string& path, const LoadProgress& progress = {});

/// A glTF 2.0 scene (.gltf with its buffers and images, or .glb) through tinygltf: its node
/// hierarchy flattened into instances, metallic-roughness materials, base-colour textures,
/// cameras, KHR_lights_punctual point lights; see docs/scenes.md. Throws lucent::Error
/// naming the file and the JSON path ("meshes[2].primitives[0].attributes.POSITION").
/// What it cannot draw and skips (line and point primitives, spot and directional lights)
/// is reported on stderr, one line each.
Scene load_gltf_scene(const std::string& path);

}  // namespace lucent::scene

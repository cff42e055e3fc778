// The hair sample's scene, built in code (no files): a head (a triangle mesh) carrying a
// head of hair (built-in cubic B-spline curves, scene/hair_strands.h) on a ground plane,
// three built-in spheres (gold metal, glass, blue coated), a key area light above and to the
// left and a cool fill point light to the right; then the node graph, with the hair in a
// GeometryGroup whose visibility mask only it has, so the key light's shadow rays can leave
// it out (light linking).
#pragma once

#include <memory>
#include <vector>

#include "lucent/context.h"
#include "scene/hair_strands.h"
#include "scene/scene.h"

namespace lucent::samples {

/// The --set options that shape the scene.
struct HairShape {
    unsigned strands = 4000;
    CurveType type = kCurveCubicBSpline;
};

/// A built-in sphere of the scene and its material.
struct HairSceneSphere {
    float3 center;
    float radius;
    scene::Material material;  // kMetal, kDielectric or kCoated
};

/// Everything of the scene as data: what tests place rays against.
struct HairSceneData {
    /// The triangle meshes (ground, head, the key light's emitter), the lights (the key light
    /// as area light 0, the fill as point light 0) and the camera.
    scene::Scene meshes;
    std::vector<HairSceneSphere> spheres;
    scene::HairStrands hair;  // empty with 0 strands
    CurveType hair_type;
    scene::Material hair_material;  // kCoated: see samples/hair/hair_programs.h
    float3 head_center;
    float head_radius;
};

HairSceneData make_hair_scene(const HairShape& shape);

/// The shadow-ray mask of each light (area lights first, then point lights): with light
/// linking the key light (area light 0) sees everything but the hair, the others see all.
std::vector<unsigned> light_masks(const scene::Scene& scene, bool light_linking);

/// What build_hair_graph made that the render needs.
struct HairGraph {
    std::shared_ptr<Node> top;
    std::shared_ptr<Buffer> light_masks;  // one unsigned per light; re-upload to relink
    std::vector<std::shared_ptr<Material>> materials;
    float scene_size = 0;
};

/// The scene's node graph in `ctx` (its ray types set by the caller): the meshes and the
/// spheres under masks kSceneMask, the hair under kHairMask, each in a GeometryGroup of its
/// own (masks on the groups keep their traversal unfiltered); the lights and the context
/// variables the closest hits read (samples/hair/hair_programs.h).
HairGraph build_hair_graph(Context& ctx, const HairSceneData& data, bool light_linking);

}  // namespace lucent::samples

// `cornell-materials`: the area-lit Cornell box with its blocks and floor given the
// physically based materials of the path tracer (metal, glass, coated), so that every
// MaterialKind renders with no scene file.
#include "lucent/error.h"
#include "scene/scene.h"

namespace lucent::scene {

Scene cornell_materials_box() {
    Scene scene = cornell_box(/*area_light=*/true);
    scene.name = "cornell-materials";
    // cornell_box builds the room as quads of two triangles, in this order: floor, ceiling,
    // back, right, left walls, then the short block's 5 faces and the tall block's 5.
    Mesh& room = scene.meshes.at(0);
    if (room.indices.size() != 30)
        throw Error("cornell_materials_box: the Cornell room has " +
                    std::to_string(room.indices.size()) +
                    " triangles, expected 30; update the face ranges here to match cornell_box");
    auto add = [&](Material m) {
        scene.materials.push_back(m);
        return unsigned(scene.materials.size() - 1);
    };
    Material varnish{"varnished white", {0.725f, 0.71f, 0.68f}};
    varnish.kind = MaterialKind::kCoated;
    varnish.roughness = 0.15f;
    varnish.ior = 1.5f;
    Material glass{"glass", {0, 0, 0}};
    glass.kind = MaterialKind::kDielectric;
    glass.ior = 1.5f;
    // Gold's reflectance at normal incidence (linear sRGB, as commonly tabulated).
    Material gold{"rough gold", {0, 0, 0}, {1.0f, 0.71f, 0.29f}};
    gold.kind = MaterialKind::kMetal;
    gold.roughness = 0.35f;
    const unsigned floor = add(varnish), short_block = add(glass), tall_block = add(gold);
    for (unsigned t = 0; t < 2; ++t) room.materials[t] = floor;
    for (unsigned t = 10; t < 20; ++t) room.materials[t] = short_block;
    for (unsigned t = 20; t < 30; ++t) room.materials[t] = tall_block;
    return scene;
}

}  // namespace lucent::scene

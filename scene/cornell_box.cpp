// The Cornell box, from the measured data of the Cornell Program of Computer Graphics
// (Goral, Torrance, Greenberg and Battaile 1984): walls, two blocks and the ceiling light.
#include <initializer_list>

#include "scene/scene.h"

namespace lucent::scene {

namespace {
struct QuadList {
    Mesh& mesh;
    /// Two triangles for a planar quad given in order around its edge.
    void add(std::initializer_list<float3> corners, unsigned material) {
        const unsigned base = unsigned(mesh.positions.size());
        mesh.positions.insert(mesh.positions.end(), corners.begin(), corners.end());
        mesh.indices.push_back(uint3{base, base + 1, base + 2});
        mesh.indices.push_back(uint3{base, base + 2, base + 3});
        mesh.materials.push_back(material);
        mesh.materials.push_back(material);
    }
};
}  // namespace

Scene cornell_box(bool area_light) {
    Scene scene;
    scene.name = area_light ? "cornell" : "cornell-point";
    // Reflectances as commonly derived from the measured spectra; light radiance (17, 12, 4).
    scene.materials = {
        {"white", {0.725f, 0.71f, 0.68f}, {0, 0, 0}, 0, {0, 0, 0}, ""},
        {"red", {0.63f, 0.065f, 0.05f}, {0, 0, 0}, 0, {0, 0, 0}, ""},
        {"green", {0.14f, 0.45f, 0.091f}, {0, 0, 0}, 0, {0, 0, 0}, ""},
        {"light", {0.78f, 0.78f, 0.78f}, {0, 0, 0}, 0, {17, 12, 4}, ""},
    };
    enum : unsigned { kWhite, kRed, kGreen, kLight };

    Mesh room;
    room.name = "room";
    QuadList q{room};
    q.add({{552.8f, 0, 0}, {0, 0, 0}, {0, 0, 559.2f}, {549.6f, 0, 559.2f}}, kWhite);  // floor
    q.add({{556, 548.8f, 0}, {556, 548.8f, 559.2f}, {0, 548.8f, 559.2f}, {0, 548.8f, 0}},
          kWhite);  // ceiling
    q.add({{549.6f, 0, 559.2f}, {0, 0, 559.2f}, {0, 548.8f, 559.2f}, {556, 548.8f, 559.2f}},
          kWhite);                                                                    // back
    q.add({{0, 0, 559.2f}, {0, 0, 0}, {0, 548.8f, 0}, {0, 548.8f, 559.2f}}, kGreen);  // right
    q.add({{552.8f, 0, 0}, {549.6f, 0, 559.2f}, {556, 548.8f, 559.2f}, {556, 548.8f, 0}},
          kRed);  // left
    // Short block.
    q.add({{130, 165, 65}, {82, 165, 225}, {240, 165, 272}, {290, 165, 114}}, kWhite);
    q.add({{290, 0, 114}, {290, 165, 114}, {240, 165, 272}, {240, 0, 272}}, kWhite);
    q.add({{130, 0, 65}, {130, 165, 65}, {290, 165, 114}, {290, 0, 114}}, kWhite);
    q.add({{82, 0, 225}, {82, 165, 225}, {130, 165, 65}, {130, 0, 65}}, kWhite);
    q.add({{240, 0, 272}, {240, 165, 272}, {82, 165, 225}, {82, 0, 225}}, kWhite);
    // Tall block.
    q.add({{423, 330, 247}, {265, 330, 296}, {314, 330, 456}, {472, 330, 406}}, kWhite);
    q.add({{423, 0, 247}, {423, 330, 247}, {472, 330, 406}, {472, 0, 406}}, kWhite);
    q.add({{472, 0, 406}, {472, 330, 406}, {314, 330, 456}, {314, 0, 456}}, kWhite);
    q.add({{314, 0, 456}, {314, 330, 456}, {265, 330, 296}, {265, 0, 296}}, kWhite);
    q.add({{265, 0, 296}, {265, 330, 296}, {423, 330, 247}, {423, 0, 247}}, kWhite);
    scene.meshes.push_back(std::move(room));

    // The light's opening in the ceiling, 0.1 mm below it so it does not coincide.
    // Edges ordered so that cross(edge1, edge2) points down, into the box: the lit side.
    const float3 corner{343, 548.7f, 227}, edge1{0, 0, 105}, edge2{-130, 0, 0};
    if (area_light) {
        Mesh light;
        light.name = "light";
        QuadList l{light};
        l.add({corner, corner + edge1, corner + edge1 + edge2, corner + edge2}, kLight);
        scene.meshes.push_back(std::move(light));
        scene.area_lights.push_back({corner, edge1, edge2, scene.materials[kLight].emission});
    } else {
        // The same power from a point: radiance x area x pi, over 4 pi steradians. It hangs
        // 10 cm below the opening, so that it lights the ceiling as well (a point light just
        // under the ceiling would pour half its power into a spot of a few millimetres).
        const float area = length(cross(edge1, edge2));
        scene.point_lights.push_back({corner + 0.5f * (edge1 + edge2) - make_float3(0, 100, 0),
                                      scene.materials[kLight].emission * (area / 4.0f)});
    }
    scene.camera = Camera{{278, 273, -800}, {278, 273, 0}, {0, 1, 0}, 39.3077f};
    return scene;
}

}  // namespace lucent::scene

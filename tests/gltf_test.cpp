// glTF 2.0 scenes (scene/gltf_scene.cpp) and instancing: files written here (embedded
// base64 buffers, GLB containers), their node transforms, one mesh shared by several
// instances (one GeometryGroup in the samples' graph), materials, cameras, lights, a render
// that hits an instanced mesh where its transform puts it, errors that name the file and
// the JSON path, truncated GLB files; and JSON scenes' "instances".
#include <gtest/gtest.h>
#include <stb_image_write.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "lucent/context.h"
#include <sys/stat.h>

#include "test_support.h"
#include "lucent/error.h"
#include "samples/sample.h"
#include "samples/scene_setup.h"
#include "samples/settings_error.h"
#include "scene/scene.h"

namespace {

namespace fs = std::filesystem;
using lucent::scene::Scene;

std::string base64(const std::string& bytes) {
    static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        const unsigned v = (unsigned char)bytes[i] << 16 | (unsigned char)bytes[i + 1] << 8 |
                           (unsigned char)bytes[i + 2];
        out += {k[v >> 18], k[(v >> 12) & 63], k[(v >> 6) & 63], k[v & 63]};
    }
    if (i + 1 == bytes.size()) {
        const unsigned v = (unsigned char)bytes[i] << 16;
        out += {k[v >> 18], k[(v >> 12) & 63], '=', '='};
    } else if (i + 2 == bytes.size()) {
        const unsigned v = (unsigned char)bytes[i] << 16 | (unsigned char)bytes[i + 1] << 8;
        out += {k[v >> 18], k[(v >> 12) & 63], k[(v >> 6) & 63], '='};
    }
    return out;
}

template <class T>
void append(std::string& bytes, const T& value) {
    bytes.append(reinterpret_cast<const char*>(&value), sizeof value);
}

/// One buffer: a unit square in z = 0 facing +z (4 positions, 6 indices as uint16, uvs),
/// and the accessors 0 (POSITION), 1 (indices), 2 (TEXCOORD_0).
std::string square_buffer() {
    std::string b;
    const float p[4][3] = {{-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, 0.5f, 0}};
    for (auto& v : p)
        for (float c : v) append(b, c);  // 48 bytes
    const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    for (uint16_t i : idx) append(b, i);  // 12 bytes, at 48
    const float uv[4][2] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    for (auto& v : uv)
        for (float c : v) append(b, c);  // 32 bytes, at 60
    return b;
}

const char* kSquareViews = R"(
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                  {"buffer": 0, "byteOffset": 48, "byteLength": 12},
                  {"buffer": 0, "byteOffset": 60, "byteLength": 32}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                 "min": [-0.5, -0.5, 0], "max": [0.5, 0.5, 0]},
                {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
                {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}])";

/// A glTF document around the square's buffer (embedded as base64); `rest` adds members.
std::string gltf(const std::string& rest, const std::string& buffer = square_buffer()) {
    return R"({"asset": {"version": "2.0"},
  "buffers": [{"byteLength": )" + std::to_string(buffer.size()) +
           R"(, "uri": "data:application/octet-stream;base64,)" + base64(buffer) + R"("}],)" +
           kSquareViews + ",\n" + rest + "}";
}

/// The square's mesh with material 0, and that material.
const char* kSquareMesh = R"(
  "meshes": [{"name": "square", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 2},
                                                "indices": 1, "material": 0}]}],
  "materials": [{"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1],
                 "metallicFactor": 0.0, "roughnessFactor": 0.4}}])";

/// A GLB container of `json` and `bin` (padded to 4 bytes as the specification asks).
std::string glb(std::string json, std::string bin) {
    while (json.size() % 4) json += ' ';
    while (bin.size() % 4) bin += '\0';
    std::string out = "glTF";
    append(out, uint32_t(2));
    append(out, uint32_t(12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size())));
    append(out, uint32_t(json.size()));
    out += "JSON" + json;
    if (bin.empty()) return out;  // the BIN chunk is optional
    append(out, uint32_t(bin.size()));
    out += std::string("BIN\0", 4) + bin;
    return out;
}

class GltfScenes : public lucent_tests::TempDirTest {
  protected:
    static std::string error_of(const std::string& path) {
        try {
            lucent::scene::load_scene(path);
        } catch (const lucent::Error& e) {
            return e.what();
        }
        return "";
    }
};

float3 world(const lucent::scene::Instance& i, float3 p) { return transform_point(i.transform, p); }

// Node 0 draws the square moved by +2 in x; node 1 is a parent rotated 90 degrees about z
// and scaled 2x, with node 2 (the square again, moved +1 in x in its parent's frame).
const char* kTwoInstances = R"(,
  "scene": 0, "scenes": [{"nodes": [0, 1]}],
  "nodes": [{"mesh": 0, "translation": [2, 0, 0]},
            {"rotation": [0, 0, 0.7071068, 0.7071068], "scale": [2, 2, 2], "children": [2]},
            {"mesh": 0, "translation": [1, 0, 0]}])";

TEST_F(GltfScenes, NodeHierarchyBecomesInstancesOfOneMesh) {
    const Scene s = lucent::scene::load_scene(write("two.gltf", gltf(std::string(kSquareMesh) + kTwoInstances)));
    ASSERT_EQ(s.meshes.size(), 1u) << "a mesh used by two nodes is stored once";
    EXPECT_EQ(s.meshes[0].name, "square");
    EXPECT_EQ(s.meshes[0].indices.size(), 2u);
    ASSERT_EQ(s.instances.size(), 2u);
    EXPECT_EQ(s.instances[0].mesh, 0u);
    EXPECT_EQ(s.instances[1].mesh, 0u);
    EXPECT_FLOAT3_NEAR(world(s.instances[0], make_float3(0.5f, 0.5f, 0)), make_float3(2.5f, 0.5f, 0), 1e-6f);
    // Parent (R_z(90) S(2)) * child (T(1, 0, 0)): (x, y) -> 2 * (-(y), x + 1) rotated.
    EXPECT_FLOAT3_NEAR(world(s.instances[1], make_float3(0, 0, 0)), make_float3(0, 2, 0), 1e-5f);
    EXPECT_FLOAT3_NEAR(world(s.instances[1], make_float3(0.5f, 0, 0)), make_float3(0, 3, 0), 1e-5f);
    EXPECT_FLOAT3_NEAR(world(s.instances[1], make_float3(0, 0.5f, 0)), make_float3(-1, 2, 0), 1e-5f);
    EXPECT_EQ(s.triangle_count(), 2u);
    EXPECT_EQ(s.drawn_triangle_count(), 4u);
    const lucent::scene::Bounds b = lucent::scene::scene_bounds(s);
    EXPECT_FLOAT3_NEAR(b.lo, make_float3(-1, -0.5f, 0), 1e-5f);
    EXPECT_FLOAT3_NEAR(b.hi, make_float3(2.5f, 3, 0), 1e-5f);
}

TEST_F(GltfScenes, InstancesShareOneGeometryGroupUnderTransforms) {
    const Scene s = lucent::scene::load_scene(write("two.gltf", gltf(std::string(kSquareMesh) + kTwoInstances)));
    lucent::Context ctx(lucent::ContextOptions{lucent::BackendKind::kCpu, 1});
    auto node = lucent::samples::place_meshes(ctx, s, {ctx.create_geometry_instance()});
    auto top = std::dynamic_pointer_cast<lucent::Group>(node);
    ASSERT_TRUE(top) << "instances hang under a Group";
    ASSERT_EQ(top->child_count(), 2u);
    auto t0 = std::dynamic_pointer_cast<lucent::Transform>(top->child(0));
    auto t1 = std::dynamic_pointer_cast<lucent::Transform>(top->child(1));
    ASSERT_TRUE(t0 && t1);
    EXPECT_EQ(t0->child(), t1->child()) << "one GeometryGroup (one BVH) for both instances";
    EXPECT_TRUE(std::dynamic_pointer_cast<lucent::GeometryGroup>(t0->child()));
    EXPECT_FLOAT_EQ(t0->matrix().m[3], 2.0f);
    // A scene without instances keeps the single GeometryGroup of all its meshes.
    const Scene cornell = lucent::scene::load_scene("cornell");
    auto flat = lucent::samples::place_meshes(
        ctx, cornell, {ctx.create_geometry_instance(), ctx.create_geometry_instance()});
    EXPECT_TRUE(std::dynamic_pointer_cast<lucent::GeometryGroup>(flat));
}

TEST_F(GltfScenes, MetallicRoughnessMaterialsAndEmission) {
    const std::string materials = R"(
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0},
                             {"attributes": {"POSITION": 0}, "indices": 1, "material": 1},
                             {"attributes": {"POSITION": 0}, "indices": 1, "material": 2},
                             {"attributes": {"POSITION": 0}, "indices": 1}]}],
  "materials": [{"name": "plastic", "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 1],
                   "metallicFactor": 0.1, "roughnessFactor": 0.3}},
                {"name": "gold", "pbrMetallicRoughness": {"baseColorFactor": [1, 0.7, 0.3, 1],
                   "metallicFactor": 1, "roughnessFactor": 0.25}},
                {"name": "lamp", "emissiveFactor": [1, 0.5, 0.25],
                 "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}}}],
  "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0, "scale": [2, 2, 2]}])";
    const Scene s = lucent::scene::load_scene(write("m.gltf", gltf(materials)));
    ASSERT_EQ(s.materials.size(), 4u);
    using lucent::scene::MaterialKind;
    EXPECT_EQ(s.materials[0].name, "plastic");
    EXPECT_EQ(s.materials[0].kind, MaterialKind::kCoated);
    EXPECT_FLOAT3_NEAR(s.materials[0].diffuse, make_float3(0.2f, 0.4f, 0.6f), 1e-6f);
    EXPECT_FLOAT_EQ(s.materials[0].roughness, 0.3f);
    EXPECT_FLOAT_EQ(s.materials[0].ior, 1.5f);
    EXPECT_EQ(s.materials[1].kind, MaterialKind::kMetal);
    EXPECT_FLOAT3_NEAR(s.materials[1].diffuse, make_float3(1, 0.7f, 0.3f), 1e-6f);
    EXPECT_FLOAT3_NEAR(s.materials[2].emission, make_float3(4, 2, 1), 1e-6f);
    EXPECT_EQ(s.materials[3].name, "glTF default");  // no material: white, metal, rough
    EXPECT_EQ(s.materials[3].kind, MaterialKind::kMetal);
    EXPECT_FLOAT_EQ(s.materials[3].roughness, 1.0f);
    ASSERT_EQ(s.meshes[0].materials.size(), 8u);
    EXPECT_EQ(s.meshes[0].materials[4], 2u);
    // The emissive primitive is two triangle lights of the scaled (2x) square: area 2 each.
    const auto lights = lucent::scene::emitter_lights(s);
    ASSERT_EQ(lights.size(), 2u);
    EXPECT_NEAR(0.5f * length(cross(lights[0].edge1, lights[0].edge2)), 2.0f, 1e-5f);
    EXPECT_FLOAT3_NEAR(lights[0].emission, make_float3(4, 2, 1), 1e-6f);
}

TEST_F(GltfScenes, BaseColourTextureIsLinearisedAndUvsFlipped) {
    // A 2x1 PNG: sRGB 255,0,0 and 0,0,188 (linear 0.5 blue, about).
    const unsigned char rgba[8] = {255, 0, 0, 255, 0, 0, 188, 255};
    std::string png;
    stbi_write_png_to_func(
        [](void* out, void* data, int size) {
            static_cast<std::string*>(out)->append(static_cast<const char*>(data), size_t(size));
        },
        &png, 2, 1, 4, rgba, 8);
    const std::string rest = R"(
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 2}, "indices": 1,
                              "material": 0}]}],
  "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
  "textures": [{"source": 0}],
  "images": [{"uri": "data:image/png;base64,)" + base64(png) + R"("}],
  "nodes": [{"mesh": 0}])";
    const std::string path = write("t.gltf", gltf(rest));
    const Scene s = lucent::scene::load_scene(path);
    ASSERT_EQ(s.textures.size(), 1u);
    const std::string& key = s.materials[0].diffuse_texture;
    ASSERT_EQ(s.textures.count(key), 1u) << key;
    const lucent::scene::TextureImage& t = s.textures.at(key);
    ASSERT_EQ(t.width, 2u);
    ASSERT_EQ(t.height, 1u);
    EXPECT_FLOAT_EQ(t.texels[0].x, 1.0f);
    EXPECT_NEAR(t.texels[1].z, 0.503f, 0.01f);
    // glTF's uv (0, 1) is the image's bottom-left; the samples read v upwards (OBJ's).
    ASSERT_EQ(s.meshes[0].uvs.size(), 4u);
    EXPECT_FLOAT_EQ(s.meshes[0].uvs[0].x, 0.0f);
    EXPECT_FLOAT_EQ(s.meshes[0].uvs[0].y, 0.0f);
    EXPECT_FLOAT_EQ(s.meshes[0].uvs[3].y, 1.0f);
}

TEST_F(GltfScenes, ExternalBufferAndImageFilesAreReadBesideTheGltfFile) {
    write("square.bin", square_buffer());
    const unsigned char rgba[4] = {0, 255, 0, 255};
    stbi_write_png((dir / "green.png").string().c_str(), 1, 1, 4, rgba, 4);
    std::string text = gltf(R"(
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 2}, "indices": 1,
                              "material": 0}]}],
  "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}}],
  "textures": [{"source": 0}], "images": [{"uri": "green.png"}],
  "nodes": [{"mesh": 0}])");
    const size_t b = text.find("\"uri\": \"data:");
    text.replace(b, text.find('"', b + 8) + 1 - b, "\"uri\": \"square.bin\"");
    const Scene s = lucent::scene::load_scene(write("external.gltf", text));
    EXPECT_FLOAT_EQ(s.meshes.at(0).positions[1].x, 0.5f);
    ASSERT_EQ(s.textures.size(), 1u);
    EXPECT_FLOAT_EQ(s.textures.begin()->second.texels[0].y, 1.0f);
    fs::remove(dir / "green.png");
    testing::internal::CaptureStderr();  // tinygltf's warning
    const std::string error = error_of((dir / "external.gltf").string());
    testing::internal::GetCapturedStderr();
    EXPECT_EQ(error.rfind((dir / "external.gltf").string() + ": ", 0), 0u) << error;
    EXPECT_NE(error.find("images[0]: 'green.png' was not loaded"), std::string::npos) << error;
}

TEST_F(GltfScenes, NamedFilesThatAreFifosOrDevicesAreRefusedByName) {
    // tinygltf opened a named file to see whether it exists: a FIFO nobody writes to
    // blocked it for ever; /dev/zero was "empty". Each is now an error naming both files.
    std::string text = gltf(std::string(kSquareMesh));
    const size_t b = text.find("\"uri\": \"data:");
    ASSERT_NE(b, std::string::npos);
    text.replace(b, text.find('"', b + 8) + 1 - b, "\"uri\": \"buffer.bin\"");
    const std::string path = write("named.gltf", text);
    ASSERT_EQ(::mkfifo((dir / "buffer.bin").c_str(), 0600), 0);
    EXPECT_EQ(error_of(path), path + ": " + (dir / "buffer.bin").string() +
                                  ": this file named by the glTF is a FIFO (named pipe), not a "
                                  "file; Lucent reads scenes, meshes and textures only from "
                                  "regular files (copy the data into one)");
    fs::remove(dir / "buffer.bin");
    // A .gltf followed by binary data: the JSON parser stopped at the NUL byte.
    const std::string padded = write("padded.gltf", gltf(kSquareMesh) + std::string(8, '\0') + "x");
    EXPECT_EQ(error_of(padded).rfind(padded + ": a NUL byte at byte ", 0), 0u) << error_of(padded);
    fs::create_symlink("/dev/zero", dir / "buffer.bin");
    EXPECT_NE(error_of(path).find("buffer.bin: this file named by the glTF is a device"),
              std::string::npos)
        << error_of(path);
}

const char* kCameras = R"(,
  "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}},
              {"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}},
              {"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}],
  "nodes": [{"mesh": 0},
            {"camera": 0, "translation": [0, 0, 5]},
            {"camera": 1, "translation": [10, 0, 0], "rotation": [0, 0.7071068, 0, 0.7071068]},
            {"camera": 2}])";

TEST_F(GltfScenes, CamerasFirstIsTheDefaultAndCameraNPicksOne) {
    const std::string path = write("c.gltf", gltf(std::string(kSquareMesh) + kCameras));
    const Scene s = lucent::scene::load_scene(path);
    ASSERT_EQ(s.cameras.size(), 3u);
    EXPECT_FLOAT3_NEAR(s.camera.eye, make_float3(0, 0, 5), 1e-6f);
    EXPECT_FLOAT3_NEAR(s.camera.look, make_float3(0, 0, 4), 1e-6f);
    EXPECT_NEAR(s.camera.fov_degrees, 0.5f * 180 / 3.14159265f, 1e-4f);
    // Camera 1 is turned 90 degrees about y: its -z looks down world -x.
    EXPECT_FLOAT3_NEAR(s.cameras[1].eye, make_float3(10, 0, 0), 1e-6f);
    EXPECT_FLOAT3_NEAR(s.cameras[1].look, make_float3(9, 0, 0), 1e-5f);
    EXPECT_FLOAT3_NEAR(s.cameras[1].up, make_float3(0, 1, 0), 1e-5f);
    EXPECT_NE(s.cameras[2].unusable.find("cameras[2]: an orthographic camera"), std::string::npos);

    lucent::samples::RenderSettings settings;
    settings.scene = path;
    settings.scene_camera = 1;
    EXPECT_FLOAT3_NEAR(lucent::samples::load_render_scene(settings).camera.eye,
                       make_float3(10, 0, 0), 1e-6f);
    settings.scene_camera = 3;
    try {
        lucent::samples::load_render_scene(settings);
        ADD_FAILURE() << "--camera 3 of 3 cameras loaded";
    } catch (const lucent::samples::SettingsError& e) {
        EXPECT_EQ(std::string(e.what()), "--camera 3: scene 'c' has 3 cameras of its own (0 to 2)");
    }
    settings.scene_camera = 2;
    EXPECT_THROW(lucent::samples::load_render_scene(settings), lucent::samples::SettingsError);
    settings.scene = "cornell";
    settings.scene_camera = 0;
    try {
        lucent::samples::load_render_scene(settings);
        ADD_FAILURE() << "--camera 0 of the Cornell box loaded";
    } catch (const lucent::samples::SettingsError& e) {
        EXPECT_EQ(std::string(e.what()), "--camera 0: scene 'cornell' has 0 cameras of its own");
    }
}

TEST_F(GltfScenes, PunctualPointLightsAreLoadedSpotAndDirectionalSkippedWithAMessage) {
    const std::string rest = std::string(kSquareMesh) + R"(,
  "extensionsUsed": ["KHR_lights_punctual"],
  "extensions": {"KHR_lights_punctual": {"lights": [
      {"type": "point", "color": [1, 0.5, 0.25], "intensity": 8},
      {"type": "spot", "intensity": 3, "spot": {}},
      {"type": "directional"}]}},
  "nodes": [{"mesh": 0},
            {"translation": [1, 2, 3], "children": [4]},
            {"extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"extensions": {"KHR_lights_punctual": {"light": 2}}},
            {"translation": [0, 1, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
  "scenes": [{"nodes": [0, 1, 2, 3]}])";
    const std::string path = write("l.gltf", gltf(rest));
    testing::internal::CaptureStderr();
    const Scene s = lucent::scene::load_scene(path);
    const std::string messages = testing::internal::GetCapturedStderr();
    ASSERT_EQ(s.point_lights.size(), 1u);
    EXPECT_FLOAT3_NEAR(s.point_lights[0].position, make_float3(1, 3, 3), 1e-6f);
    EXPECT_FLOAT3_NEAR(s.point_lights[0].intensity, make_float3(8, 4, 2), 1e-6f);
    EXPECT_NE(messages.find(path + ": nodes[2].extensions.KHR_lights_punctual.light: a spot light; "
                                   "the samples have point and area lights only, skipped"),
              std::string::npos)
        << messages;
    EXPECT_NE(messages.find("nodes[3].extensions.KHR_lights_punctual.light: a directional light"),
              std::string::npos)
        << messages;
}

TEST_F(GltfScenes, RenderHitsTheInstancedMeshWhereItsTransformPutsIt) {
    // Two instances of a red square, at x = -1.5 and x = +1.5 (the second scaled 0.5), seen
    // by a camera at z = 6 with a point light beside it; the middle of the image is empty.
    const std::string rest = std::string(kSquareMesh) + R"(,
  "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 40}]}},
  "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}],
  "nodes": [{"mesh": 0, "translation": [-1.5, 0, 0]},
            {"mesh": 0, "translation": [1.5, 0, 0], "scale": [0.5, 0.5, 0.5]},
            {"camera": 0, "translation": [0, 0, 6]},
            {"translation": [0, 0, 5], "extensions": {"KHR_lights_punctual": {"light": 0}}}])";
    const std::string path = write("r.glb", glb(gltf(rest), ""));
    lucent::samples::RenderSettings settings;
    settings.width = settings.height = 64;
    settings.backend = lucent_tests::test_backend();  // LUCENT_TEST_BACKEND=cuda: the GPU
    settings.threads = 2;
    settings.scene = path;
    const auto r = lucent::samples::find_sample("direct").render(settings);
    auto pixel = [&](float3 p) {  // the pixel world point p projects to
        const float half = std::tan(0.35f), z = 6.0f - p.z;
        const int x = int((p.x / z / half * 0.5f + 0.5f) * 64), y = int((0.5f - p.y / z / half * 0.5f) * 64);
        return r.image.pixels[size_t(y) * 64 + size_t(x)];
    };
    const float3 left = pixel(make_float3(-1.5f, 0, 0)), right = pixel(make_float3(1.5f, 0, 0));
    const float3 gap = pixel(make_float3(0, 0, 0)), outside_small = pixel(make_float3(1.5f, 0.4f, 0));
    EXPECT_GT(left.x, 0.05f);
    EXPECT_GT(left.x, 4 * left.y) << "red";
    EXPECT_GT(right.x, 0.05f);
    EXPECT_EQ(gap.x + gap.y + gap.z, 0.0f);
    EXPECT_EQ(outside_small.x + outside_small.y + outside_small.z, 0.0f)
        << "the scaled instance reaches 0.25 from its centre, not 0.4";
}

TEST_F(GltfScenes, ShadingNormalsOfANonUniformlyScaledInstanceAreByTheInverseTranspose) {
    // The square at x = -1.5 facing the light (+z), and at x = +1.5 turned 45 degrees about y
    // and then stretched 3x along x (matrix S R). The plane's normal is then
    // (sin 45 / 3, 0, cos 45) normalised, 18.4 degrees from +z (cosine 0.949); transformed by
    // the matrix itself it would be (3 sin 45, 0, cos 45), 71.6 degrees off (cosine 0.316).
    // A far light on +z lights the two in the ratio of the cosines.
    const std::string rest = std::string(kSquareMesh) + R"(,
  "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 100000}]}},
  "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}],
  "nodes": [{"mesh": 0, "translation": [-1.5, 0, 0]},
            {"mesh": 0, "matrix": [2.1213203, 0, -0.7071068, 0,  0, 1, 0, 0,
                                   2.1213203, 0, 0.7071068, 0,  1.5, 0, 0, 1]},
            {"camera": 0, "translation": [0, 0, 6]},
            {"translation": [0, 0, 100], "extensions": {"KHR_lights_punctual": {"light": 0}}}])";
    lucent::samples::RenderSettings settings;
    settings.width = settings.height = 64;
    settings.backend = lucent_tests::test_backend();  // LUCENT_TEST_BACKEND=cuda: the GPU
    settings.threads = 2;
    settings.scene = write("n.gltf", gltf(rest));
    const auto r = lucent::samples::find_sample("direct").render(settings);
    auto pixel = [&](float x) {  // the pixel of world point (x, 0, 0)
        const int px = int((x / 6.0f / std::tan(0.35f) * 0.5f + 0.5f) * 64);
        return r.image.pixels[size_t(32) * 64 + size_t(px)];
    };
    const float reference = pixel(-1.5f).x, tilted = pixel(1.5f).x;
    ASSERT_GT(reference, 0.1f);
    // The light, seen from the two centres, leans 0.86 degrees inwards (towards x = 0): away
    // from the tilted normal, so cos(18.43 + 0.86) / cos(0.86) = 0.944.
    EXPECT_NEAR(tilted / reference, 0.944f, 0.005f);
}

TEST_F(GltfScenes, MalformedFilesNameTheFileAndTheJsonPath) {
    const std::string mesh_bad_accessor = R"(
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1},
                             {"attributes": {"POSITION": 7}}]}],
  "nodes": [{"mesh": 0}])";
    const std::string bad = write("scene.gltf", gltf(mesh_bad_accessor));
    EXPECT_EQ(error_of(bad), bad + ": meshes[0].primitives[1].attributes.POSITION: accessor 7 is "
                                   "out of range (the file has 3)");

    const std::string bad_mesh = write("m.gltf", gltf(R"("nodes": [{"mesh": 4}], "meshes": [])"));
    EXPECT_EQ(error_of(bad_mesh), bad_mesh + ": nodes[0].mesh: mesh 4 is out of range (the file has 0)");

    const std::string bad_index = write("i.gltf", gltf(R"(
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "nodes": [{"mesh": 0}])", [] {
        std::string b = square_buffer();
        b[48 + 4] = 9;  // the third index: 9 of 4 vertices
        return b;
    }()));
    EXPECT_EQ(error_of(bad_index), bad_index + ": meshes[0].primitives[0].indices: index 9 "
                                               "(element 2) is out of range (POSITION has 4 vertices)");

    // An accessor overrunning its view: 5 positions in a view of 4.
    std::string overrun = gltf(std::string(kSquareMesh) + R"(, "nodes": [{"mesh": 0}])");
    overrun.replace(overrun.find("\"count\": 4, \"type\": \"VEC3\""), 26, "\"count\": 5, \"type\": \"VEC3\"");
    const std::string over = write("o.gltf", overrun);
    EXPECT_EQ(error_of(over), over + ": accessors[0]: 5 elements from byte 0 overrun bufferView 0 of 48 bytes");

    const std::string missing = write("missing.gltf", R"({"asset": {"version": "2.0"},
  "buffers": [{"byteLength": 92, "uri": "nowhere.bin"}]})");
    const std::string missing_error = error_of(missing);
    EXPECT_EQ(missing_error.rfind(missing + ": ", 0), 0u) << missing_error;
    EXPECT_NE(missing_error.find("nowhere.bin"), std::string::npos) << missing_error;

    const std::string syntax = write("s.gltf", R"({"asset": {"version": "2.0"}, "nodes": [)");
    EXPECT_EQ(error_of(syntax).rfind(syntax + ": ", 0), 0u) << error_of(syntax);

    // An empty file: its bytes' data() is null, which memchr (the NUL byte check) must not
    // be given (UBSan in fuzz.scene_gltf once; tests/fuzz/corpus/gltf/empty.gltf too).
    const std::string empty = write("empty.gltf", "");
    EXPECT_EQ(error_of(empty).rfind(empty + ": ", 0), 0u) << error_of(empty);

    const std::string cycle = write("cycle.gltf", gltf(std::string(kSquareMesh) + R"(,
  "nodes": [{"children": [1]}, {"mesh": 0, "children": [0]}], "scenes": [{"nodes": [0]}])"));
    EXPECT_EQ(error_of(cycle), cycle + ": nodes[1].children[0]: node 0 is its own ancestor (a cycle)");

    const std::string twice = write("twice.gltf", gltf(std::string(kSquareMesh) + R"(,
  "nodes": [{"children": [2]}, {"children": [2]}, {"mesh": 0}], "scenes": [{"nodes": [0, 1]}])"));
    EXPECT_EQ(error_of(twice), twice + ": nodes[1].children[0]: node 2 is reached a second time "
                                       "(a node has one parent at most)");

    const std::string draco = write("d.gltf", gltf(std::string(kSquareMesh) + R"(,
  "extensionsRequired": ["KHR_draco_mesh_compression"], "nodes": [{"mesh": 0}])"));
    EXPECT_EQ(error_of(draco), draco + ": extensionsRequired[0]: the file requires "
                                       "KHR_draco_mesh_compression, which Lucent does not read");
}

TEST_F(GltfScenes, LinePrimitivesAreSkippedWithAMessageStripsAndFansConverted) {
    const std::string rest = R"(
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 1},
                             {"attributes": {"POSITION": 0}, "mode": 5},
                             {"attributes": {"POSITION": 0}, "mode": 6}]}],
  "nodes": [{"mesh": 0}])";
    const std::string path = write("lines.gltf", gltf(rest));
    testing::internal::CaptureStderr();
    const Scene s = lucent::scene::load_scene(path);
    const std::string messages = testing::internal::GetCapturedStderr();
    EXPECT_NE(messages.find(path + ": meshes[0].primitives[0].mode: mode 1 (LINES) draws no "
                                   "triangles; Lucent renders triangles, skipped"),
              std::string::npos)
        << messages;
    ASSERT_EQ(s.meshes[0].indices.size(), 4u) << "a strip and a fan of 4 vertices: 2 each";
    // The strip's odd triangles swap a pair to keep one winding (glTF 2.0 §3.7.2.1: p1 p3
    // p2); the fan's all share its first vertex. The skipped lines add no vertices: 0..3
    // are the strip's, 4..7 the fan's.
    const auto& t = s.meshes[0].indices;
    auto same_cycle = [](uint3 a, uint3 b) {
        return (a.x == b.x && a.y == b.y && a.z == b.z) || (a.x == b.y && a.y == b.z && a.z == b.x) ||
               (a.x == b.z && a.y == b.x && a.z == b.y);
    };
    EXPECT_EQ(s.meshes[0].positions.size(), 8u);
    EXPECT_TRUE(same_cycle(t[0], make_uint3(0, 1, 2)));
    EXPECT_TRUE(same_cycle(t[1], make_uint3(1, 3, 2)));
    EXPECT_TRUE(same_cycle(t[2], make_uint3(4, 5, 6)));
    EXPECT_TRUE(same_cycle(t[3], make_uint3(4, 6, 7)));

    const std::string only_lines = write("only.gltf", gltf(R"(
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 3}]}], "nodes": [{"mesh": 0}])"));
    testing::internal::CaptureStderr();
    const std::string error = error_of(only_lines);
    testing::internal::GetCapturedStderr();
    EXPECT_EQ(error, only_lines + ": scenes: the scene draws no triangles");
}

TEST_F(GltfScenes, GlbLoadsAndEveryTruncationIsAnErrorNotACrash) {
    const std::string bin = square_buffer();
    std::string json = gltf(std::string(kSquareMesh) + R"(, "nodes": [{"mesh": 0}])", bin);
    // The GLB's buffer 0 is its BIN chunk: no uri.
    const size_t b = json.find("\"buffers\"");
    const size_t e = json.find("}],", b);
    json.replace(b, e + 3 - b, "\"buffers\": [{\"byteLength\": " + std::to_string(bin.size()) + "}],");
    const std::string file = glb(json, bin);
    const Scene whole = lucent::scene::load_scene(write("whole.glb", file));
    EXPECT_EQ(whole.meshes.at(0).indices.size(), 2u);
    EXPECT_FLOAT_EQ(whole.meshes[0].positions[2].x, 0.5f);
    for (size_t n = 0; n < file.size(); n += (n < 40 ? 1 : 7)) {
        const std::string path = write("cut.glb", file.substr(0, n));
        testing::internal::CaptureStderr();
        const std::string error = error_of(path);
        testing::internal::GetCapturedStderr();
        EXPECT_EQ(error.rfind(path + ": ", 0), 0u) << n << " bytes: " << error;
    }
}

TEST_F(GltfScenes, JsonScenesPlaceMeshesByInstances) {
    const std::string path = write("i.json", R"({
  "meshes": [{"positions": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,2]]}],
  "instances": [{"mesh": 0, "translate": [5, 0, 0]},
                {"mesh": 0, "rotate": [0, 0, 1, 90], "scale": 2},
                {"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,-3]}],
  "lights": [{"type": "point", "position": [0, 0, 5], "intensity": [1, 1, 1]}]})");
    const Scene s = lucent::scene::load_scene(path);
    ASSERT_EQ(s.meshes.size(), 1u);
    ASSERT_EQ(s.instances.size(), 3u);
    EXPECT_FLOAT3_NEAR(world(s.instances[0], make_float3(1, 0, 0)), make_float3(6, 0, 0), 1e-6f);
    EXPECT_FLOAT3_NEAR(world(s.instances[1], make_float3(1, 0, 0)), make_float3(0, 2, 0), 1e-5f);
    EXPECT_FLOAT3_NEAR(world(s.instances[2], make_float3(0, 1, 0)), make_float3(0, 1, -3), 1e-6f);

    const std::string unplaced = write("u.json", R"({
  "meshes": [{"positions": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,2]]},
             {"positions": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,2]]}],
  "instances": [{"mesh": 0}]})");
    EXPECT_EQ(error_of(unplaced),
              unplaced + ": /meshes/1: no instance places this mesh; with \"instances\" only "
                         "placed meshes are drawn (add {\"mesh\": 1} or remove it)");
    const std::string singular = write("z.json", R"({
  "meshes": [{"positions": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,2]]}],
  "instances": [{"mesh": 0, "scale": 0}]})");
    EXPECT_EQ(error_of(singular),
              singular + ": /instances/0: the transform is singular (a zero scale); rays could "
                         "not enter it");
    const std::string out_of_range = write("r.json", R"({
  "meshes": [{"positions": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,2]]}],
  "instances": [{"mesh": 1}]})");
    EXPECT_EQ(error_of(out_of_range), out_of_range + ": /instances/0/mesh: expected the index of "
                                                     "an entry of /meshes, 0..1 (exclusive)");
}

}  // namespace

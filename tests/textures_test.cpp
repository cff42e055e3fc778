// Diffuse textures (map_Kd in an MTL, "texture" in JSON) in IGI and the path tracer,
// checked against values: a checkerboard floor whose pixels must be the texel they show
// times the light the untextured floor gets (IGI paper §4.2: rho multiplies the irradiance
// at full resolution, after downsampling and filtering), the direct sample's image where
// both compute the same thing, and a two-colour texture that must light the room exactly as
// per-quad colours do (the VPLs' radiance is rho at their own point).
#include <gtest/gtest.h>
#include <stb_image_write.h>

#include <cmath>
#include <fstream>
#include <map>
#include <vector>

#include "samples/sample.h"
#include "scene/texture_image.h"
#include "test_support.h"

namespace {

using lucent::samples::RenderResult;
using lucent::samples::RenderSettings;
using Sets = std::map<std::string, std::string>;

RenderResult render(const std::string& sample, const std::string& scene, unsigned size,
                    const Sets& sets, unsigned spp = 0, bool layers = false) {
    RenderSettings settings;
    settings.width = settings.height = size;
    settings.backend = lucent_tests::test_backend();  // LUCENT_TEST_BACKEND=cuda: the GPU
    settings.threads = 2;
    settings.scene = scene;
    settings.sets = sets;
    settings.keep_layers = layers;
    if (spp) settings.spp = spp;
    return lucent::samples::find_sample(sample).render(settings);
}

/// An axis-aligned quad as OBJ text: four corners, their texture coordinates, one face.
std::string obj_quad(const std::vector<float3>& corners, const std::vector<float2>& uvs,
                     const std::string& material, unsigned& base) {
    std::string s = "usemtl " + material + "\n";
    for (const float3& c : corners)
        s += "v " + std::to_string(c.x) + " " + std::to_string(c.y) + " " + std::to_string(c.z) + "\n";
    for (const float2& t : uvs) s += "vt " + std::to_string(t.x) + " " + std::to_string(t.y) + "\n";
    s += "f";
    for (unsigned i = 1; i <= 4; ++i) s += " " + std::to_string(base + i) + "/" + std::to_string(base + i);
    base += 4;
    return s + "\n";
}

// ---- the checkerboard floor -----------------------------------------------------------------
// A 4 x 4 floor (y = 0) under a point light, a grey back wall behind it. The floor's texture
// is 16 x 16 texels: a 4 x 4 checkerboard of white and dark squares, 4 x 4 texels each, so a
// square's middle (from its first to its last texel centre) is one colour after bilinear
// filtering. Its uv is ((x + 2) / 4, (2 - z) / 4).
constexpr int kTexels = 16, kSquare = 4;
constexpr unsigned char kDark = 64;  // sRGB; linear about 0.05

class CheckerFloor : public lucent_tests::TempDirTest {
  protected:
    void SetUp() override {
        TempDirTest::SetUp();
        std::vector<unsigned char> rgb;
        for (int y = 0; y < kTexels; ++y)
            for (int x = 0; x < kTexels; ++x) {
                const bool white = ((x / kSquare) + (y / kSquare)) % 2 == 0;
                // Coloured dark squares: each channel its own value, so a swapped channel shows.
                const unsigned char d[3] = {kDark, kDark / 2, kDark / 4};
                for (int c = 0; c < 3; ++c) rgb.push_back(white ? 255 : d[c]);
            }
        stbi_write_png((dir / "checker.png").string().c_str(), kTexels, kTexels, 3, rgb.data(),
                       kTexels * 3);
        texture = lucent::scene::load_texture((dir / "checker.png").string());
        write("checker.mtl", "newmtl floor\nKd 1 1 1\nmap_Kd checker.png\n"
                             "newmtl wall\nKd 0.8 0.8 0.8\n");
        write("plain.mtl", "newmtl floor\nKd 1 1 1\nnewmtl wall\nKd 0.8 0.8 0.8\n");
        unsigned base = 0;  // the quads in this order: each numbers its vertices after the last
        std::string quads = obj_quad({{-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2}},
                                     {{0, 0}, {1, 0}, {1, 1}, {0, 1}}, "floor", base);
        quads += obj_quad({{-2, 0, -2}, {2, 0, -2}, {2, 4, -2}, {-2, 4, -2}},
                          {{0, 0}, {1, 0}, {1, 1}, {0, 1}}, "wall", base);
        write("checker.obj", "mtllib checker.mtl\n" + quads);
        write("plain.obj", "mtllib plain.mtl\n" + quads);
        const std::string rest = R"(
            "camera": {"eye": [0, 2.5, 4.5], "look": [0, 0.6, -0.5], "fov": 55},
            "lights": [{"type": "point", "position": [0.5, 2.5, 1], "intensity": [6, 6, 6]}]})";
        textured = write("checker.json", R"({"meshes": [{"file": "checker.obj"}],)" + rest);
        plain = write("plain.json", R"({"meshes": [{"file": "plain.obj"}],)" + rest);
    }

    /// The texel a floor point shows when it lies in the middle of a square (bilinear
    /// filtering gives exactly that square's colour there); false near a square's edge.
    bool pure_texel(float3 position, float3& texel) const {
        const float u = (position.x + 2.0f) / 4.0f, v = (2.0f - position.z) / 4.0f;
        // OBJ's v runs up the image; texel row 0 is its top (sample_common::diffuse_texel).
        const float tx = u * kTexels, ty = (1.0f - v) * kTexels;
        const float fx = std::fmod(tx, float(kSquare)), fy = std::fmod(ty, float(kSquare));
        if (tx < 0 || ty < 0 || tx >= kTexels || ty >= kTexels) return false;
        if (fx < 1.0f || fx > 3.0f || fy < 1.0f || fy > 3.0f) return false;  // 1 texel inside
        const float4 t = texture.texels[size_t(ty) * kTexels + size_t(tx)];
        texel = make_float3(t.x, t.y, t.z);
        return true;
    }

    lucent::scene::TextureImage texture;
    std::string textured, plain;
};

float3 at(const lucent::scene::Image& image, size_t i) {
    return image.pixels[i];
}

bool near_rel(float3 a, float3 b, float rel, float abs = 1e-6f) {
    const float3 d = a - b;
    const float scale = rel * max_component(fmaxf(a, b)) + abs;
    return fabsf(d.x) <= scale && fabsf(d.y) <= scale && fabsf(d.z) <= scale;
}

TEST_F(CheckerFloor, IgiKeepsTheTextureOnEveryPathOfItsIndirectLight) {
    // Every pixel of the floor is its rho times what the white floor receives: the direct
    // light and the upsampled, filtered irradiance alike. The floor's lighting does not
    // depend on its own texture (its VPLs light the wall, never the plane they lie on), so
    // this holds to rounding, at every pixel, squares' edges too: were rho applied before
    // downsampling or filtering, the squares would blur into each other.
    const Sets configurations[] = {
        {},
        {{"downsample", "4"}},
        {{"interleave", "3"}},
        {{"downsample", "2"}, {"interleave", "3"}, {"imperfect_visibility", "1"}},
    };
    for (const Sets& sets : configurations) {
        std::string name;
        for (auto& [k, v] : sets) name += k + "=" + v + " ";
        const RenderResult t = render("igi", textured, 96, sets, 0, true);
        const RenderResult u = render("igi", plain, 96, sets, 0, true);
        const lucent::scene::Image& albedo = t.layers.at("albedo");
        const lucent::scene::Image& position = t.layers.at("position");
        const lucent::scene::Image& normal = t.layers.at("normal");
        size_t floor = 0, white = 0, dark = 0, wrong = 0;
        for (size_t i = 0; i < t.image.pixels.size(); ++i) {
            const float3 p = position.pixels[i];
            EXPECT_EQ(u.layers.at("position").pixels[i].x, p.x) << name << "the same G-buffer";
            // The floor's pixels: an upward normal (the background's G-buffer is zero).
            if (!(normal.pixels[i].y > 0.99f) || max_component(at(u.image, i)) <= 0.0f) continue;
            ++floor;
            const float3 expected = at(albedo, i) * at(u.image, i);
            if (!near_rel(at(t.image, i), expected, 2e-5f)) {
                if (++wrong < 5)
                    ADD_FAILURE() << name << "pixel " << i << ": " << at(t.image, i).x << " "
                                  << at(t.image, i).y << " " << at(t.image, i).z
                                  << ", expected rho x untextured " << expected.x << " "
                                  << expected.y << " " << expected.z;
            }
            float3 texel;
            if (pure_texel(p, texel)) {
                // The G-buffer's rho is the texel (Kd 1), and the ratio to the white floor is
                // what the texture says.
                EXPECT_TRUE(near_rel(at(albedo, i), texel, 1e-5f)) << name << "pixel " << i;
                ++(texel.x > 0.9f ? white : dark);
            }
        }
        EXPECT_EQ(wrong, 0u) << name;
        EXPECT_GT(floor, 2000u) << name << ": the floor fills a good part of the image";
        EXPECT_GT(white, 200u) << name;
        EXPECT_GT(dark, 200u) << name;
    }
}

TEST_F(CheckerFloor, IgiWithoutIndirectLightIsTheDirectSample) {
    // min_d = 10 scene sizes bounds every VPL away: IGI's image is its direct stage, which
    // computes what the direct sample does (the same point light, rho / pi, shadow rays):
    // pixel for pixel, the same texels.
    const RenderResult igi = render("igi", textured, 64, {{"min_d", "10"}});
    const RenderResult direct = render("direct", textured, 64, {});
    ASSERT_EQ(igi.image.pixels.size(), direct.image.pixels.size());
    size_t lit = 0;
    for (size_t i = 0; i < igi.image.pixels.size(); ++i) {
        EXPECT_TRUE(near_rel(at(igi.image, i), at(direct.image, i), 1e-5f)) << "pixel " << i;
        if (max_component(at(direct.image, i)) > 0.0f) ++lit;
    }
    EXPECT_GT(lit, 2000u);
}

TEST_F(CheckerFloor, ThePathTracersAlbedoAndDirectLightShowTheTexels) {
    // Two path segments: the camera's ray and next-event estimation of the point light, so
    // the path tracer's image is the direct sample's, averaged over each pixel's footprint
    // (jittered) where the direct sample takes its centre. In a square's middle both see one
    // texel; the light varies little across a pixel. Its AOV albedo is the texel itself.
    RenderSettings settings;
    settings.width = settings.height = 64;
    settings.backend = lucent_tests::test_backend();
    settings.threads = 2;
    settings.scene = textured;
    settings.spp = 16;
    settings.sets = {{"max_depth", "2"}};
    settings.aovs.albedo = settings.aovs.position = true;
    const auto& sample = lucent::samples::find_sample("pathtracer");
    const RenderResult pt = sample.render(settings);
    const RenderResult direct = render("direct", textured, 64, {});
    std::map<std::string, const std::vector<float>*> aov;
    for (const auto& c : pt.aovs) aov[c.name] = &c.values;
    ASSERT_TRUE(aov.count("Albedo.R") && aov.count("Px")) << "AOV channels";
    // Per square colour: the sums of both images over its pixels, and the pixels' worst
    // ratio (the jitter's noise: 16 points in a footprint across which the light varies by
    // a few per cent near the wall).
    double sum_pt[2] = {0, 0}, sum_direct[2] = {0, 0}, worst = 0;
    size_t count[2] = {0, 0};
    for (size_t i = 0; i < pt.image.pixels.size(); ++i) {
        const float3 p = make_float3((*aov["Px"])[i], (*aov["Py"])[i], (*aov["Pz"])[i]);
        float3 texel;
        if (!(std::fabs(p.y) < 1e-3f) || !pure_texel(p, texel)) continue;
        // The pixel's footprint (about 0.1 texel here) must lie in the square's middle too.
        float3 unused;
        if (!pure_texel(p + make_float3(0.05f, 0, 0.05f), unused) ||
            !pure_texel(p - make_float3(0.05f, 0, 0.05f), unused))
            continue;
        const float3 albedo =
            make_float3((*aov["Albedo.R"])[i], (*aov["Albedo.G"])[i], (*aov["Albedo.B"])[i]);
        EXPECT_TRUE(near_rel(albedo, texel, 1e-5f)) << "pixel " << i << ": AOV albedo";
        const float3 a = at(pt.image, i), b = at(direct.image, i);
        ASSERT_GT(b.z, 0.0f) << "pixel " << i << " is lit";
        // The colour is the texel's exactly: one light, white, the same rho in every sample.
        EXPECT_NEAR(a.z / a.x, texel.z / texel.x, 1e-4f) << "pixel " << i;
        worst = std::max(worst, std::fabs(a.x / b.x - 1.0));
        const int k = texel.x > 0.9f ? 0 : 1;
        sum_pt[k] += a.x;
        sum_direct[k] += b.x;
        ++count[k];
    }
    EXPECT_LT(worst, 0.04) << "a pixel against the direct sample's";
    for (int k : {0, 1}) {
        EXPECT_GT(count[k], 100u) << (k ? "dark" : "white") << " pixels";
        EXPECT_NEAR(sum_pt[k] / sum_direct[k], 1.0, 0.005) << (k ? "dark" : "white") << " squares";
    }
}

// ---- a texture is Kd where it lies ---------------------------------------------------------
// A floor of two quads: mapped onto a 4 x 1 texture (red, red, blue, blue) so that the left
// quad shows only its red half and the right quad its blue half, or given those colours as
// Kd. A grey back wall takes the floor's colour from its VPLs; a mirror on the right shows
// the floor (the specular tree, and the reflection layer of the G-buffer).
class TwoColourFloor : public lucent_tests::TempDirTest {
  protected:
    void SetUp() override {
        TempDirTest::SetUp();
        const unsigned char rgb[12] = {255, 0, 0, 255, 0, 0, 0, 0, 255, 0, 0, 255};
        stbi_write_png((dir / "rb.png").string().c_str(), 4, 1, 3, rgb, 12);
        unsigned base = 0;
        write("left.obj", obj_quad({{-2, 0, 2}, {0, 0, 2}, {0, 0, -2}, {-2, 0, -2}},
                                   {{0.125f, 0.5f}, {0.375f, 0.5f}, {0.375f, 0.5f}, {0.125f, 0.5f}},
                                   "m", base));
        base = 0;
        write("right.obj", obj_quad({{0, 0, 2}, {2, 0, 2}, {2, 0, -2}, {0, 0, -2}},
                                    {{0.625f, 0.5f}, {0.875f, 0.5f}, {0.875f, 0.5f}, {0.625f, 0.5f}},
                                    "m", base));
        base = 0;
        write("wall.obj", obj_quad({{-2, 0, -2}, {2, 0, -2}, {2, 4, -2}, {-2, 4, -2}},
                                   {{0, 0}, {1, 0}, {1, 1}, {0, 1}}, "m", base));
        base = 0;
        write("mirror.obj", obj_quad({{1.6f, 0, 2}, {1.6f, 0, -2}, {1.6f, 3, -2}, {1.6f, 3, 2}},
                                     {{0, 0}, {1, 0}, {1, 1}, {0, 1}}, "m", base));
        textured = scene("textured", "red_blue", "red_blue");
        coloured = scene("coloured", "red", "blue");
        white = scene("white", "white", "white");
    }

    std::string scene(const std::string& name, const std::string& left, const std::string& right) {
        return write(name + ".json", R"({
            "camera": {"eye": [-0.5, 2.2, 4.5], "look": [0.3, 0.6, -0.5], "fov": 60},
            "materials": [
              {"name": "red_blue", "diffuse": [0.8, 0.8, 0.8], "texture": "rb.png"},
              {"name": "red", "diffuse": [0.8, 0, 0]},
              {"name": "blue", "diffuse": [0, 0, 0.8]},
              {"name": "white", "diffuse": [0.8, 0.8, 0.8]},
              {"name": "grey", "diffuse": [0.7, 0.7, 0.7]},
              {"name": "mirror", "diffuse": [0, 0, 0], "specular": [0.8, 0.8, 0.8]}],
            "meshes": [{"file": "left.obj", "material": ")" + left + R"("},
                       {"file": "right.obj", "material": ")" + right + R"("},
                       {"file": "wall.obj", "material": "grey"},
                       {"file": "mirror.obj", "material": "mirror"}],
            "lights": [{"type": "point", "position": [-0.5, 3, 1], "intensity": [8, 8, 8]}]})");
    }

    std::string textured, coloured, white;
};

double relative_rms(const lucent::scene::Image& a, const lucent::scene::Image& b) {
    double squared = 0, total = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i) {
        const float3 d = a.pixels[i] - b.pixels[i];
        squared += dot(d, d);
        total += a.pixels[i].x + a.pixels[i].y + a.pixels[i].z;
    }
    const double mean = total / (3.0 * a.pixels.size());
    return std::sqrt(squared / (3.0 * a.pixels.size())) / mean;
}

TEST_F(TwoColourFloor, IgiLightsTheRoomWithTheTexelsItsVplsLieOn) {
    // The textured floor and the coloured one are one image: the wall's indirect light
    // comes from VPLs whose radiance is rho at their own point (its texel, not Kd alone),
    // two bounces carry it on, and the mirror shows the texture through the specular tree,
    // inline or as the reflection layer. That the floor's colour reaches the wall at all is
    // checked against a white floor.
    const Sets configurations[] = {
        {},
        {{"bounces", "2"}},
        {{"reflection_layer", "0"}},
        {{"downsample", "4"}, {"interleave", "3"}},
    };
    for (const Sets& sets : configurations) {
        std::string name;
        for (auto& [k, v] : sets) name += k + "=" + v + " ";
        const RenderResult t = render("igi", textured, 64, sets);
        const RenderResult c = render("igi", coloured, 64, sets);
        EXPECT_LT(relative_rms(c.image, t.image), 1e-4) << name;
        size_t differing = 0;
        for (size_t i = 0; i < t.image.pixels.size(); ++i)
            if (!near_rel(at(t.image, i), at(c.image, i), 1e-3f)) ++differing;
        EXPECT_EQ(differing, 0u) << name;
    }
    const RenderResult w = render("igi", white, 64, {});
    const RenderResult c = render("igi", coloured, 64, {});
    EXPECT_GT(relative_rms(w.image, c.image), 0.05) << "the floor's colour shows";
    // The wall (top middle of the image) is lit by the floor's VPLs: with a white floor its
    // green channel gets light, with the red and blue one none but the direct light's.
    const float3 wall_w = at(w.image, size_t(10) * 64 + 32), wall_c = at(c.image, size_t(10) * 64 + 32);
    EXPECT_GT(wall_w.y, wall_c.y * 1.05f) << "indirect light from the floor on the wall";
}

TEST_F(TwoColourFloor, ThePathTracerShadesTheTexelsAsColours) {
    // The same equivalence for the path tracer: same seed, same paths, the same image to
    // rounding (a texel lookup instead of Kd changes no random number).
    const RenderResult t = render("pathtracer", textured, 32, {{"seed", "3"}}, 8);
    const RenderResult c = render("pathtracer", coloured, 32, {{"seed", "3"}}, 8);
    EXPECT_LT(relative_rms(c.image, t.image), 1e-4);
    const RenderResult w = render("pathtracer", white, 32, {{"seed", "3"}}, 8);
    EXPECT_GT(relative_rms(w.image, c.image), 0.05);
}

// ---- a glTF-style metal: its colour, and its texture, come from the base colour -----------
TEST_F(TwoColourFloor, AMetalWhoseColourIsItsBaseColourIsTintedByItsTexture) {
    // A "metal" with only `diffuse` is how glTF's metallic materials arrive: the base colour
    // is the conductor's F0, and its texture tints that too. The left half must come out
    // red, the right half blue, as the coloured metals do.
    auto metal_scene = [&](const std::string& name, const std::string& left,
                           const std::string& right) {
        return write(name + ".json", R"({
            "camera": {"eye": [0, 3, 3], "look": [0, 0, 0], "fov": 70},
            "materials": [
              {"name": "red_blue", "type": "metal", "roughness": 0.8, "diffuse": [0.9, 0.9, 0.9],
               "texture": "rb.png"},
              {"name": "red", "type": "metal", "roughness": 0.8, "diffuse": [0.9, 0, 0]},
              {"name": "blue", "type": "metal", "roughness": 0.8, "diffuse": [0, 0, 0.9]}],
            "meshes": [{"file": "left.obj", "material": ")" + left + R"("},
                       {"file": "right.obj", "material": ")" + right + R"("}],
            "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [8, 8, 8]}]})");
    };
    const RenderResult t =
        render("pathtracer", metal_scene("metal_t", "red_blue", "red_blue"), 32, {{"seed", "5"}}, 8);
    const RenderResult c =
        render("pathtracer", metal_scene("metal_c", "red", "blue"), 32, {{"seed", "5"}}, 8);
    EXPECT_LT(relative_rms(c.image, t.image), 1e-4);
    const float3 left = at(t.image, size_t(16) * 32 + 8), right = at(t.image, size_t(16) * 32 + 24);
    EXPECT_GT(left.x, 0.0f);
    EXPECT_LT(left.z, 1e-4f * left.x) << "the left half is red metal";
    EXPECT_GT(right.z, 0.0f);
    EXPECT_LT(right.x, 1e-4f * right.z) << "the right half is blue metal";
}

}  // namespace

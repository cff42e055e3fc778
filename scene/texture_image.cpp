#include "scene/texture_image.h"

#include <stb_image.h>

#include <cmath>
#include <filesystem>
#include <memory>

#include "lucent/error.h"
#include "scene/input_file.h"
#include "scene/exr_encoder.h"

namespace lucent::scene {

namespace {
constexpr uint64_t kMaxTexels = kMaxImagePixels;

void check_declared_size(const std::string& path, const char* what) {
    require_regular_file(path, what);
    int width = 0, height = 0, channels = 0;
    if (!stbi_info(path.c_str(), &width, &height, &channels)) return;  // stbi_load says why
    if (uint64_t(width) * uint64_t(height) > kMaxTexels)
        throw Error("the " + std::string(what) + " '" + path + "' declares " +
                    std::to_string(width) + " x " + std::to_string(height) +
                    " pixels, more than the " + std::to_string(kMaxTexels) +
                    " a texture may have; resize it (or check that the file is not damaged)");
}
}  // namespace

float srgb_to_linear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

TextureImage load_texture(const std::string& path) {
    check_declared_size(path, "texture");
    int width = 0, height = 0, channels = 0;
    std::unique_ptr<unsigned char, void (*)(void*)> data(
        stbi_load(path.c_str(), &width, &height, &channels, 4), stbi_image_free);
    if (!data) {
        const char* reason = stbi_failure_reason();
        throw Error("cannot read the texture '" + path +
                    "': " + (reason ? reason : "unknown format"));
    }
    // A lookup table: 256 entries instead of a pow per channel.
    float to_linear[256];
    for (int i = 0; i < 256; ++i) to_linear[i] = srgb_to_linear(i / 255.0f);
    TextureImage image;
    image.width = unsigned(width);
    image.height = unsigned(height);
    image.texels.resize(size_t(width) * height);
    const unsigned char* p = data.get();
    for (size_t i = 0; i < image.texels.size(); ++i, p += 4)
        image.texels[i] =
            make_float4(to_linear[p[0]], to_linear[p[1]], to_linear[p[2]], p[3] / 255.0f);
    return image;
}

TextureImage load_linear_image(const std::string& path) {
    const std::string ext = std::filesystem::path(path).extension().string();
    TextureImage image;
    if (ext == ".exr") {
        const Image rgb = read_exr(path);
        image.width = rgb.width;
        image.height = rgb.height;
        for (const float3& p : rgb.pixels) image.texels.push_back(make_float4(p.x, p.y, p.z, 1.0f));
        return image;
    }
    if (ext != ".hdr")
        throw Error("cannot read the environment map '" + path +
                    "': expected a linear .hdr or .exr file");
    check_declared_size(path, "environment map");
    int width = 0, height = 0, channels = 0;
    std::unique_ptr<float, void (*)(void*)> data(
        stbi_loadf(path.c_str(), &width, &height, &channels, 4), stbi_image_free);
    if (!data) {
        const char* reason = stbi_failure_reason();
        throw Error("cannot read the environment map '" + path +
                    "': " + (reason ? reason : "not a Radiance .hdr file"));
    }
    image.width = unsigned(width);
    image.height = unsigned(height);
    image.texels.resize(size_t(width) * height);
    const float* p = data.get();
    for (size_t i = 0; i < image.texels.size(); ++i, p += 4)
        image.texels[i] = make_float4(p[0], p[1], p[2], 1.0f);
    return image;
}

}  // namespace lucent::scene

#include "scene/image_read.h"

#include <stb_image.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "lucent/error.h"
#include "scene/exr_encoder.h"
#include "scene/input_file.h"
#include "scene/texture_image.h"

namespace lucent::scene {

namespace {

constexpr uint64_t kMaxPixels = kMaxImagePixels;

std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

void check_pixel_count(const std::string& path, uint64_t width, uint64_t height) {
    if (width == 0 || height == 0 || width * height > kMaxPixels)
        throw Error("image '" + path + "': " + std::to_string(width) + " x " +
                    std::to_string(height) + " pixels; an image holds 1 to " +
                    std::to_string(kMaxPixels) + " pixels");
}

/// Portable float map: "PF" (RGB) or "Pf" (grey), "width height", a scale whose sign is the
/// byte order (negative: little-endian), then rows of floats from the bottom up.
Image read_pfm(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error("cannot open the image '" + path + "'");
    std::string magic;
    uint64_t width = 0, height = 0;
    double scale = 0;
    in >> magic >> width >> height >> scale;
    if (!in || (magic != "PF" && magic != "Pf") || scale == 0 || !std::isfinite(scale))
        throw Error("image '" + path +
                    "': not a PFM header (expected 'PF' or 'Pf', width, height and a non-zero "
                    "scale)");
    check_pixel_count(path, width, height);
    in.get();  // the single whitespace byte after the scale
    const unsigned channels = magic == "PF" ? 3 : 1;
    const uint64_t count = width * height * channels;
    const uint64_t data_start = uint64_t(in.tellg());
    if (file_size(path) != data_start + count * sizeof(float))
        throw Error("image '" + path + "': its header declares " + std::to_string(width) + " x " +
                    std::to_string(height) + " pixels (" +
                    std::to_string(count * sizeof(float)) + " bytes) but " +
                    std::to_string(file_size(path) - std::min(file_size(path), data_start)) +
                    " bytes follow it");
    std::vector<float> values(count);
    in.read(reinterpret_cast<char*>(values.data()), std::streamsize(count * sizeof(float)));
    if (!in) throw Error("image '" + path + "': could not read its pixels");
    const bool file_little_endian = scale < 0;
    const bool host_little_endian = std::endian::native == std::endian::little;
    if (file_little_endian != host_little_endian)
        for (float& v : values) {
            uint32_t u;
            std::memcpy(&u, &v, 4);
            u = __builtin_bswap32(u);
            std::memcpy(&v, &u, 4);
        }
    Image image;
    image.width = unsigned(width);
    image.height = unsigned(height);
    image.pixels.resize(width * height);
    for (uint64_t y = 0; y < height; ++y)
        for (uint64_t x = 0; x < width; ++x) {
            const float* p = &values[((height - 1 - y) * width + x) * channels];
            image.pixels[y * width + x] =
                channels == 3 ? make_float3(p[0], p[1], p[2]) : make_float3(p[0]);
        }
    return image;
}

/// stb_image's formats: 8-bit ones decoded from sRGB, Radiance .hdr as stored.
Image read_with_stb(const std::string& path, bool linear) {
    int width = 0, height = 0, channels = 0;
    if (!stbi_info(path.c_str(), &width, &height, &channels))
        throw Error("cannot read the image '" + path + "': " +
                    (stbi_failure_reason() ? stbi_failure_reason() : "unknown format"));
    check_pixel_count(path, uint64_t(width), uint64_t(height));
    Image image;
    image.width = unsigned(width);
    image.height = unsigned(height);
    image.pixels.resize(size_t(width) * height);
    if (linear) {
        std::unique_ptr<float, void (*)(void*)> data(
            stbi_loadf(path.c_str(), &width, &height, &channels, 3), stbi_image_free);
        if (!data) throw Error("cannot read the image '" + path + "': " + stbi_failure_reason());
        for (size_t i = 0; i < image.pixels.size(); ++i)
            image.pixels[i] = make_float3(data.get()[3 * i], data.get()[3 * i + 1],
                                          data.get()[3 * i + 2]);
        return image;
    }
    std::unique_ptr<unsigned char, void (*)(void*)> data(
        stbi_load(path.c_str(), &width, &height, &channels, 3), stbi_image_free);
    if (!data) throw Error("cannot read the image '" + path + "': " + stbi_failure_reason());
    float to_linear[256];
    for (int i = 0; i < 256; ++i) to_linear[i] = srgb_to_linear(float(i) / 255.0f);
    const unsigned char* p = data.get();
    for (size_t i = 0; i < image.pixels.size(); ++i, p += 3)
        image.pixels[i] = make_float3(to_linear[p[0]], to_linear[p[1]], to_linear[p[2]]);
    return image;
}

}  // namespace

Image read_image(const std::string& path) {
    require_regular_file(path, "image");
    if (!std::filesystem::exists(path)) throw Error("image '" + path + "': no such file");
    const std::string ext = lower_extension(path);
    if (ext == ".exr") return read_exr(path);
    if (ext == ".pfm") return read_pfm(path);
    if (ext == ".hdr") return read_with_stb(path, /*linear=*/true);
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tga")
        return read_with_stb(path, /*linear=*/false);
    throw Error("image '" + path +
                "': unknown extension; read are .exr, .pfm, .hdr (linear) and .png, .jpg, .bmp, "
                ".tga (sRGB)");
}

}  // namespace lucent::scene

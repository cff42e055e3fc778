#include "screenshot.h"

#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "lucent/error.h"
#include "present/gl.h"
#include "scene/image_io.h"

namespace lucent::viewer {
namespace {

/// The sRGB transfer function's inverse (IEC 61966-2-1), the decoding of an 8-bit code.
float linear_from_srgb8(unsigned char code) {
    const float c = float(code) / 255.0f;
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

void write_png(const std::string& path, int width, int height,
               const std::vector<unsigned char>& rgb) {
    const std::string temporary = path + ".tmp";
    if (!stbi_write_png(temporary.c_str(), width, height, 3, rgb.data(), width * 3))
        throw Error("cannot write '" + path + "': PNG encoding or the write failed");
    std::error_code ec;
    std::filesystem::rename(temporary, path, ec);
    if (ec) {
        std::remove(temporary.c_str());
        throw Error("cannot write '" + path + "': " + ec.message());
    }
}

}  // namespace

void save_framebuffer(const std::string& path, int width, int height) {
    std::vector<unsigned char> rgb(size_t(width) * height * 3);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rgb.data());
    // OpenGL's rows start at the bottom; the files' at the top.
    std::vector<unsigned char> flipped(rgb.size());
    const size_t row = size_t(width) * 3;
    for (int y = 0; y < height; ++y)
        std::copy_n(rgb.data() + size_t(height - 1 - y) * row, row,
                    flipped.data() + size_t(y) * row);
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".png") return write_png(path, width, height, flipped);
    scene::Image image;
    image.width = unsigned(width);
    image.height = unsigned(height);
    image.pixels.resize(size_t(width) * height);
    for (size_t i = 0; i < image.pixels.size(); ++i)
        image.pixels[i] =
            make_float3(linear_from_srgb8(flipped[3 * i]), linear_from_srgb8(flipped[3 * i + 1]),
                        linear_from_srgb8(flipped[3 * i + 2]));
    scene::write_image(path, image);  // .exr or .pfm: the command checked the name
}

}  // namespace lucent::viewer

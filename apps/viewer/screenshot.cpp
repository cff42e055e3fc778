#include "screenshot.h"

#include <stb_image_write.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "present/gl.h"
#include "lucent/error.h"

namespace lucent::viewer {

void save_framebuffer_png(const std::string& path, int width, int height) {
    std::vector<unsigned char> rgb(size_t(width) * height * 3);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rgb.data());
    // OpenGL's rows start at the bottom; PNG's at the top.
    std::vector<unsigned char> flipped(rgb.size());
    const size_t row = size_t(width) * 3;
    for (int y = 0; y < height; ++y)
        std::copy_n(rgb.data() + size_t(height - 1 - y) * row, row,
                    flipped.data() + size_t(y) * row);
    const std::string temporary = path + ".tmp";
    if (!stbi_write_png(temporary.c_str(), width, height, 3, flipped.data(), int(row)))
        throw Error("cannot write '" + path + "': PNG encoding or the write failed");
    std::error_code ec;
    std::filesystem::rename(temporary, path, ec);
    if (ec) {
        std::remove(temporary.c_str());
        throw Error("cannot write '" + path + "': " + ec.message());
    }
}

}  // namespace lucent::viewer

#include "window_readback.h"

#include <algorithm>

#include "present/gl.h"

namespace lucent::viewer {

std::vector<unsigned char> read_window_rgba(int width, int height) {
    std::vector<unsigned char> rgba(size_t(width) * height * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    // OpenGL's rows start at the bottom; display frames' at the top.
    const size_t row = size_t(width) * 4;
    for (int y = 0; y < height / 2; ++y)
        std::swap_ranges(rgba.begin() + ptrdiff_t(y * row), rgba.begin() + ptrdiff_t((y + 1) * row),
                         rgba.begin() + ptrdiff_t((height - 1 - y) * row));
    return rgba;
}

size_t count_differing_rgb(const std::vector<unsigned char>& a,
                           const std::vector<unsigned char>& b) {
    if (a.size() != b.size()) return std::max(a.size(), b.size()) / 4;
    size_t differ = 0;
    for (size_t i = 0; i + 3 < a.size(); i += 4)
        if (a[i] != b[i] || a[i + 1] != b[i + 1] || a[i + 2] != b[i + 2]) ++differ;
    return differ;
}

}  // namespace lucent::viewer

// Reads back what the window shows, to compare it with the frame that was rendered: the
// soak's check that every frame reaches the window unchanged (`lucent view --soak`).
#pragma once

#include <cstddef>
#include <vector>

namespace lucent::viewer {

/// The pixels of the current framebuffer just drawn (the back buffer, before the swap), RGBA8
/// with row 0 at the top, as display frames hold them.
std::vector<unsigned char> read_window_rgba(int width, int height);

/// How many pixels of two RGBA8 images of the same size differ in red, green or blue (alpha
/// is not compared: the window's is always opaque).
size_t count_differing_rgb(const std::vector<unsigned char>& a,
                           const std::vector<unsigned char>& b);

}  // namespace lucent::viewer

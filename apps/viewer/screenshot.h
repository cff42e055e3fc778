// Saves what the window shows (the headless check's --screenshot).
#pragma once

#include <string>

namespace lucent::viewer {

/// Reads the current framebuffer (glReadPixels) and writes it as an 8-bit RGB PNG, atomically
/// (a temporary file renamed). Throws lucent::Error naming the path.
void save_framebuffer_png(const std::string& path, int width, int height);

}  // namespace lucent::viewer

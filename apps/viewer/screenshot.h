// Saves what the window shows (the headless check's --screenshot).
#pragma once

#include <string>

namespace lucent::viewer {

/// Reads the current framebuffer (glReadPixels) and writes it by the path's extension: an
/// 8-bit RGB PNG as it is, or .exr / .pfm (scene::write_image) with the 8-bit sRGB pixels
/// decoded to linear floats; atomically (a temporary file renamed). Throws lucent::Error
/// naming the path.
void save_framebuffer(const std::string& path, int width, int height);

}  // namespace lucent::viewer

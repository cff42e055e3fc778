// OpenEXR encoding (Debian's libopenexr-dev): linear float RGB, the format renderers and
// compositors read without loss.
#pragma once

#include <string>
#include <vector>

#include "scene/image_io.h"

namespace lucent::scene {

/// True when this build links OpenEXR.
bool exr_supported();
/// The image as an OpenEXR file in memory (32-bit float R, G, B; ZIP compression).
/// Throws lucent::Error naming `path` when encoding fails or OpenEXR is not built in.
std::vector<unsigned char> encode_exr(const std::string& path, const Image& image);
/// Reads the R, G, B channels of an OpenEXR file as floats (for tests and comparisons).
Image read_exr(const std::string& path);

}  // namespace lucent::scene

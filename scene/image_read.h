// Images in, by file extension, as linear RGB: what `lucent compare` and lucent.compare read.
#pragma once

#include <string>

#include "scene/image_io.h"

namespace lucent::scene {

/// .exr (OpenEXR, R G B), .pfm (PF colour or Pf grey, either byte order) and .hdr (Radiance)
/// as stored; .png, .jpg, .bmp, .tga (stb_image) decoded from sRGB. Row 0 at the top.
/// Throws lucent::Error naming the file and what is wrong with it (unknown extension, not a
/// regular file, a header that does not parse, a size the file does not hold, more pixels
/// than 2^27).
Image read_image(const std::string& path);

}  // namespace lucent::scene

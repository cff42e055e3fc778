// Image textures: any format stb_image reads (PNG, JPEG, TGA, BMP, ...), as linear float4
// texels, row 0 at the top. Colour channels are sRGB-encoded in such files and linearised;
// alpha is linear already.
#pragma once

#include <string>
#include <vector>

#include "lucent/device/vector_math.h"

namespace lucent::scene {

struct TextureImage {
    unsigned width = 0, height = 0;
    std::vector<float4> texels;
};

/// Throws lucent::Error naming the file and stb_image's reason.
TextureImage load_texture(const std::string& path);

/// A linear high-dynamic-range image, as environment maps come: Radiance .hdr (stb_image) or
/// OpenEXR .exr; no transfer function applied. Throws lucent::Error naming the file and the
/// reason, or the extensions it reads.
TextureImage load_linear_image(const std::string& path);

}  // namespace lucent::scene

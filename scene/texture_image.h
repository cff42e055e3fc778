// Image textures: any format stb_image reads (PNG, JPEG, TGA, BMP, ...), as linear float4
// texels, row 0 at the top. Colour channels are sRGB-encoded in such files and linearised;
// alpha is linear already.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "lucent/device/vector_math.h"

namespace lucent::scene {

struct TextureImage {
    unsigned width = 0, height = 0;
    std::vector<float4> texels;
};

/// The most pixels an image file may declare (textures, environment maps, images read for
/// comparison): 2^27 (2 GiB as float4), e.g. 11,585 x 11,585. A header is read before its
/// pixels: a small file that claims 16,000 x 16,000 would otherwise take gigabytes and
/// minutes before anything could be said.
inline constexpr uint64_t kMaxImagePixels = uint64_t(1) << 27;

/// The sRGB transfer function's inverse (IEC 61966-2-1).
float srgb_to_linear(float c);

/// Throws lucent::Error naming the file and stb_image's reason.
TextureImage load_texture(const std::string& path);

/// A linear high-dynamic-range image, as environment maps come: Radiance .hdr (stb_image) or
/// OpenEXR .exr; no transfer function applied. Throws lucent::Error naming the file and the
/// reason, or the extensions it reads.
TextureImage load_linear_image(const std::string& path);

}  // namespace lucent::scene

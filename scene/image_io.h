// Images in and out: PNG (8-bit sRGB), OpenEXR and PFM (float), chosen by file extension.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "lucent/device/vector_math.h"

namespace lucent::scene {

/// A linear-RGB float image, row 0 at the top.
struct Image {
    unsigned width = 0, height = 0;
    std::vector<float3> pixels;
};

/// Linear [0,1] to 8-bit sRGB (clamped; lucent::srgb8_from_linear), RGB interleaved, row 0
/// first.
std::vector<unsigned char> to_srgb8(const Image& image);

/// An image file type write_image writes: its extension, lower case, and what it holds.
struct ImageFormat {
    const char* extension;
    const char* what;  // "8-bit sRGB"
};
/// Every one, in the order errors list them: .png, .exr, .pfm.
std::span<const ImageFormat> image_formats();
/// "must end in .png (8-bit sRGB), .exr (OpenEXR, float) or .pfm (32-bit float, linear)".
std::string image_formats_text();
/// Whether `path`'s extension (any case) is one of image_formats().
bool has_image_extension(const std::string& path);

/// Writes .png (8-bit sRGB) or .pfm (32-bit float, linear) by extension. Writes to a
/// temporary file beside `path` and renames it, so a failure never leaves a partial file.
/// Throws lucent::Error naming the path and the reason.
void write_image(const std::string& path, const Image& image);

struct ExrExtras;  // scene/exr_encoder.h
/// The same with extra channels and header attributes, which only OpenEXR holds: a path
/// other than .exr with non-empty extras is a lucent::Error that says to use .exr.
void write_image(const std::string& path, const Image& image, const ExrExtras& extras);

/// Writes 8-bit RGBA pixels (row 0 at the top, e.g. a lucent::DisplayFrame's) as an RGB PNG,
/// through a temporary file like write_image. Throws lucent::Error naming the path.
void write_png_rgba8(const std::string& path, unsigned width, unsigned height,
                     const std::vector<unsigned char>& rgba);

/// An 8-bit RGB PNG as stored (no colour conversion), for golden-image comparisons.
struct Image8 {
    unsigned width = 0, height = 0;
    std::vector<unsigned char> rgb;
};
Image8 read_png8(const std::string& path);

/// HIPRT-style comparison: the number of pixels where any channel differs by more than
/// `threshold` (out of 255).
size_t count_differing_pixels(const Image8& a, const Image8& b, int threshold = 10);

}  // namespace lucent::scene

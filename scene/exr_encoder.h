// OpenEXR encoding (Debian's libopenexr-dev): linear float RGB, the format renderers and
// compositors read without loss, with optional extra channels (alpha, AOV layers) and string
// attributes in the header (the render's metadata).
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "scene/image_io.h"

namespace lucent::scene {

/// One extra 32-bit float channel: `values` has one entry per pixel, row 0 at the top. Named
/// as OpenEXR's layer convention has it, "Layer.Channel" ("Albedo.R") or plain ("A", "Z").
struct ExrChannel {
    std::string name;
    std::vector<float> values;
};

/// What an EXR file carries beside R, G, B: extra channels and string header attributes
/// (written as Imf::StringAttribute under these names).
struct ExrExtras {
    std::vector<ExrChannel> channels;
    std::vector<std::pair<std::string, std::string>> attributes;
    bool empty() const { return channels.empty() && attributes.empty(); }
};

/// True when this build links OpenEXR.
bool exr_supported();
/// The image as an OpenEXR file in memory (32-bit float R, G, B and `extras`' channels; ZIP
/// compression). Throws lucent::Error naming `path` when encoding fails, a channel has the
/// wrong number of values or a reserved name (R, G, B, or twice), or OpenEXR is not built in.
std::vector<unsigned char> encode_exr(const std::string& path, const Image& image,
                                      const ExrExtras& extras = {});
/// Reads the R, G, B channels of an OpenEXR file as floats (for tests and comparisons).
Image read_exr(const std::string& path);

/// Everything read_exr_file finds: R, G, B, every other channel (as float) and the header's
/// string attributes.
struct ExrFile {
    Image image;
    std::map<std::string, std::vector<float>> channels;
    std::map<std::string, std::string> attributes;
};
ExrFile read_exr_file(const std::string& path);

}  // namespace lucent::scene

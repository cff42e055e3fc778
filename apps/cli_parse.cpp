// Value parsers of the command line (see cli_parse.h).
#include "cli_parse.h"

#include <CLI/CLI.hpp>

#include "scene/exr_encoder.h"
#include "scene/image_io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <sstream>

namespace lucent::cli {

std::string quoted(const std::string& text) {
    return "'" + text + "'";
}

namespace {

/// A whole-string number; false on trailing junk, overflow or a non-finite value.
template <class T>
bool parse_number(std::string_view text, T& value) {
    if (!text.empty() && text[0] == '+') text.remove_prefix(1);  // from_chars rejects '+'
    if (text.empty()) return false;
    auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || ptr != text.data() + text.size()) return false;
    if constexpr (std::is_floating_point_v<T>) return std::isfinite(value);
    return true;
}

}  // namespace

Size parse_size(const std::string& flag, const std::string& text) {
    const std::string form = "; expected WxH with each side in [1, " +
                             std::to_string(kMaxImageSide) + "], e.g. 1024x768";
    const size_t x = text.find_first_of("xX");
    unsigned width = 0, height = 0;
    if (x == std::string::npos || !parse_number(std::string_view(text).substr(0, x), width) ||
        !parse_number(std::string_view(text).substr(x + 1), height))
        throw UsageError(flag + " " + quoted(text) + ": not a size" + form);
    if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide)
        throw UsageError(flag + " " + quoted(text) + ": size out of range" + form);
    return {width, height};
}

float3 parse_vec3(const std::string& flag, const std::string& text) {
    float v[3] = {0, 0, 0};
    std::string_view rest = text;
    for (int i = 0; i < 3; ++i) {
        const size_t comma = i < 2 ? rest.find(',') : std::string_view::npos;
        const std::string_view part = rest.substr(0, comma);
        if ((i < 2 && comma == std::string_view::npos) || !parse_number(part, v[i]))
            throw UsageError(flag + " " + quoted(text) +
                             ": expected three numbers x,y,z without spaces, e.g. 0,1.5,-3");
        if (i < 2) rest.remove_prefix(comma + 1);
    }
    return make_float3(v[0], v[1], v[2]);
}

float parse_float(const std::string& flag, const std::string& text, float lo, float hi, bool open) {
    float value = 0;
    const bool ok = parse_number(std::string_view(text), value);
    if (!ok || (open ? (value <= lo || value >= hi) : (value < lo || value > hi))) {
        std::ostringstream msg;
        msg << flag << " " << quoted(text) << ": expected a number in " << (open ? "(" : "[") << lo
            << ", " << hi << (open ? ")" : "]");
        throw UsageError(msg.str());
    }
    return value;
}

BackendKind parse_backend(const std::string& flag, const std::string& text) {
    std::string lower = text;
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (lower == "auto") return BackendKind::kAuto;
    if (lower == "cpu") return BackendKind::kCpu;
    if (lower == "cuda") return BackendKind::kCuda;
    throw UsageError(flag + " " + quoted(text) + ": expected auto, cpu or cuda");
}

std::vector<DeviceSpec> parse_devices(const std::string& flag, const std::string& text) {
    if (text.empty()) return {};
    try {
        return parse_device_list(text);
    } catch (const Error& e) {
        throw UsageError(flag + ": " + e.what());
    }
}

void add_devices_option(CLI::App* command, std::string& devices) {
    command
        ->add_option("--devices", devices,
                     "Spread each launch over these devices: GPU numbers and cpu, or all "
                     "(replaces --backend)")
        ->type_name("0,1|cpu,0|all");
}

int parse_sm(const std::string& flag, const std::string& text) {
    std::string digits = text.rfind("sm_", 0) == 0 ? text.substr(3) : text;
    int sm = 0;
    bool ok = !digits.empty() && digits.size() <= 3;
    for (char c : digits) ok = ok && std::isdigit(static_cast<unsigned char>(c));
    if (ok) sm = std::stoi(digits);
    if (!ok || sm < 50 || sm > 200)
        throw UsageError(flag + " " + quoted(text) +
                         ": expected a GPU architecture such as sm_90 (sm_50 .. sm_200)");
    return sm;
}

std::pair<std::string, std::string> parse_set(const std::string& flag, const std::string& text) {
    const size_t eq = text.find('=');
    if (eq == std::string::npos || eq == 0)
        throw UsageError(flag + " " + quoted(text) +
                         ": expected NAME=VALUE (`lucent render --help` lists each sample's "
                         "options)");
    return {text.substr(0, eq), text.substr(eq + 1)};
}

void check_image_path(const std::string& flag, const std::string& path) {
    namespace fs = std::filesystem;
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (!scene::has_image_extension(path))
        throw UsageError(flag + " " + quoted(path) + ": the file name " +
                         scene::image_formats_text());
    if (ext == ".exr" && !scene::exr_supported())
        throw UsageError(flag + " " + quoted(path) +
                         ": this build has no OpenEXR (install libopenexr-dev); use .pfm");
    const fs::path dir = fs::path(path).parent_path();
    std::error_code ec;
    if (!dir.empty() && !fs::is_directory(dir, ec))
        throw UsageError(flag + " " + quoted(path) + ": the directory " + quoted(dir.string()) +
                         " does not exist");
    if (fs::is_directory(path, ec))
        throw UsageError(flag + " " + quoted(path) + ": is a directory; give a file name");
}

}  // namespace lucent::cli

// Parsing of the command line's value forms (WxH, x,y,z, name=value, backends), with
// messages that name the flag, the value and the accepted form.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>

#include "lucent/context.h"

namespace CLI {
class App;
}
#include "lucent/device/vector_math.h"

namespace lucent::cli {

/// Bad command-line input (exit code 2); the message names the flag and the accepted form.
class UsageError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

struct Size {
    unsigned width = 0, height = 0;
};

constexpr unsigned kMaxImageSide = 16384;

/// "1024x768" → {1024, 768}; each side in [1, kMaxImageSide].
Size parse_size(const std::string& flag, const std::string& text);
/// "1,2.5,-3" → float3; three finite numbers.
float3 parse_vec3(const std::string& flag, const std::string& text);
/// A finite number in (lo, hi) when `open`, else [lo, hi].
float parse_float(const std::string& flag, const std::string& text, float lo, float hi,
                  bool open = false);
/// "auto", "cpu" or "cuda".
BackendKind parse_backend(const std::string& flag, const std::string& text);
/// A --devices list ("0,1", "cpu,0", "all"); empty text: none (the --backend device).
std::vector<DeviceSpec> parse_devices(const std::string& flag, const std::string& text);
/// Adds the --devices option (its text for parse_devices) to a command that renders.
void add_devices_option(CLI::App* command, std::string& devices);
/// 'text', for messages that quote what the user typed.
std::string quoted(const std::string& text);
/// "sm_90" or "90" → 90; UsageError naming the flag otherwise.
int parse_sm(const std::string& flag, const std::string& text);
/// "name=value" → {name, value}; the name is non-empty, the value may be empty.
std::pair<std::string, std::string> parse_set(const std::string& flag, const std::string& text);
/// An image path whose extension is one of scene::image_formats() (and .exr only in a build with
/// OpenEXR) in a directory that exists.
void check_image_path(const std::string& flag, const std::string& path);

}  // namespace lucent::cli

// Device-side sources compiled into the binary as text, for NVRTC: the device API headers,
// the GPU runtime and traversal, and every sample's program module.
#pragma once

#include <string_view>
#include <vector>

namespace lucent::cuda {

struct EmbeddedSource {
    std::string_view name;  // include path, e.g. "lucent/device/api.h"
    std::string_view text;
};

const std::vector<EmbeddedSource>& embedded_sources();

/// The source whose name equals `name` or ends with "/" + name, or null.
const EmbeddedSource* find_embedded_source(std::string_view name);

}  // namespace lucent::cuda

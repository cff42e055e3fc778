// Device-side sources compiled into the library as text, for NVRTC: the device API headers
// and the GPU runtime and traversal. Program modules bring their own (lucent/module.h).
#pragma once

#include <string_view>
#include <vector>

namespace lucent::cuda {

struct EmbeddedSource {
    std::string_view name;  // include path, e.g. "lucent/device/api.h"
    std::string_view text;
};

const std::vector<EmbeddedSource>& embedded_sources();

}  // namespace lucent::cuda

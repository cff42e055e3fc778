// The device API headers (include/lucent/device.h and include/lucent/device/), compiled
// into the library as text: modules compiled at run time for the CPU backend include them
// (runtime_module.cpp), whether or not the headers are installed beside the program.
#pragma once

#include <string_view>
#include <vector>

namespace lucent::core {

struct EmbeddedSource {
    std::string_view name;  // include path, e.g. "lucent/device/api.h"
    std::string_view text;
};

const std::vector<EmbeddedSource>& device_headers();

}  // namespace lucent::core

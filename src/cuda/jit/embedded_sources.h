// Device-side sources compiled into the library as text, for NVRTC: the device API headers
// and the GPU runtime and traversal. Program modules bring their own (lucent/module.h).
#pragma once

#include <vector>

#include "core/device_headers.h"

namespace lucent::cuda {

using core::EmbeddedSource;  // one (include path, text) pair, as the CPU's headers are kept

const std::vector<EmbeddedSource>& embedded_sources();

}  // namespace lucent::cuda

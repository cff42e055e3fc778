// `lucent view` for the fog sample.
#pragma once

#include <memory>

#include "samples/sample.h"

namespace lucent::samples {

/// The fog scene built once; the camera is already data in a buffer (FogScene).
std::unique_ptr<InteractiveSession> open_fog_session(const RenderSettings& settings);

}  // namespace lucent::samples

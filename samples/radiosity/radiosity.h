// The instant radiosity sample (the seed blog): photons, merged VPLs, deferred shading.
#pragma once

#include "samples/sample.h"

namespace lucent::samples {

const SampleInfo& radiosity_sample_info();

}  // namespace lucent::samples

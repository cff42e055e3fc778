// The progressive path tracer sample (seed CACM §6.2).
#pragma once

#include "samples/sample.h"

namespace lucent::samples {

const SampleInfo& pathtracer_sample_info();

}  // namespace lucent::samples

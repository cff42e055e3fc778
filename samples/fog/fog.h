// The volumetric fog sample (Sebald, seed §3.1): the OptiX SDK tutorial scene with TEA-noise fog.
#pragma once

#include "samples/sample.h"

namespace lucent::samples {

const SampleInfo& fog_sample_info();

}  // namespace lucent::samples

// The Instant Global Illumination sample (Marques and Santos, seed §4) with its accelerations.
#pragma once

#include "samples/sample.h"

namespace lucent::samples {

const SampleInfo& igi_sample_info();

}  // namespace lucent::samples

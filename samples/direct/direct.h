// The direct-lighting sample: any scene (built-in, OBJ or JSON) with Lambertian surfaces,
// emission, point lights and area lights with shadow rays. Programs in direct_programs.h.
#pragma once

#include "samples/sample.h"

namespace lucent::samples {

/// The sample's name, options and render function, for the registry.
const SampleInfo& direct_sample_info();

}  // namespace lucent::samples

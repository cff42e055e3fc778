// The render loop of a progressive sample (one sample per pixel per launch, accumulated in a
// buffer on the device): the launches, the first one's compile stages and report, and the
// steady-state frame time as samples per pixel per second.
#pragma once

#include "lucent/context.h"
#include "samples/sample.h"

namespace lucent::samples {

/// Launches entry 0 settings.spp times (`default_spp` when 0) over the image and adds the
/// stages "compile + accel" (and "megakernel JIT"), "launch (frame)" (the median of every
/// frame but the first, which compiled) and "render" (all of them, with samples per pixel
/// per second) to `out`; out.report is the first launch's, or the first with exceptions.
void render_progressive(Context& ctx, const RenderSettings& settings, unsigned default_spp,
                        RenderResult& out);

}  // namespace lucent::samples

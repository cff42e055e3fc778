// The Whitted scene as a building block: the sample's render and its interactive session
// (`lucent view`) build the same scene and differ only in their camera program.
#pragma once

#include <memory>

#include "samples/sample.h"

namespace lucent::samples {

/// The sample's --set options, checked.
struct WhittedOptions {
    int antialiasing = 0;
    float aa_threshold = 0.1f;
    int max_depth = 6;
    int shadows = 1;
    int lights = 1;
};

/// Reads and checks the options, the scene name and the size; SettingsError on bad input.
WhittedOptions read_whitted_options(const RenderSettings& settings);

/// Builds everything but the ray-generation program into `ctx`; returns the float4 output
/// buffer (context variable output_buffer) of width x height.
std::shared_ptr<Buffer> build_whitted_scene(Context& ctx, const WhittedOptions& options,
                                            unsigned width, unsigned height);

/// The sample's interactive session: the camera from a buffer (whitted_view_camera).
std::unique_ptr<InteractiveSession> open_whitted_session(const RenderSettings& settings);

}  // namespace lucent::samples

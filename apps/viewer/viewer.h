// The interactive viewer behind `lucent view`: a GLFW window, the render on a worker thread,
// an ImGui panel. Built only with GLFW, Dear ImGui and OpenGL (LUCENT_HAVE_VIEWER).
#pragma once

#include <string>

#include "samples/sample.h"

namespace lucent::viewer {

struct ViewerConfig {
    const samples::Sample* sample = nullptr;
    samples::RenderSettings settings;
    unsigned frames = 0;     // >0: exit after this many rendered frames were shown
    std::string screenshot;  // with frames: save the window's pixels here (.png .exr .pfm)
    bool panel = true;
    float ui_scale = 0;  // 0: the window's content scale
    samples::ViewDenoiser denoiser = samples::ViewDenoiser::kOff;
    bool verbose = false;
    bool fit_window = false;  // render at the window's size, following its resizes
    double soak = 0;          // >0: drive the window this many seconds, checking (soak.h)
};

/// Opens the window and runs until it is closed (or `frames` were shown, or the soak ended);
/// returns the exit code. Throws lucent::Error when no window can be opened.
int run_viewer(const ViewerConfig& config);

}  // namespace lucent::viewer

// `lucent bench present`: what the viewer's presentation path costs per frame, timed in a
// headless OpenGL context (no window or display server needed). A sample session renders
// frames as display frames (RenderSettings::display_frames); each is then shown the way
// `lucent view` shows it (ImageView::show, one draw, glFinish), through CUDA–OpenGL interop
// and through a host upload.
#pragma once

#include <functional>
#include <string>

#include "lucent/context.h"

namespace lucent::bench {

struct PresentBenchOptions {
    std::string sample = "whitted";
    BackendKind backend = BackendKind::kAuto;
    unsigned threads = 0;
    unsigned width = 1920, height = 1080;
    unsigned frames = 100;  // timed per path, after 3 warm-up frames
    bool json = false;
    std::function<void(unsigned, unsigned)> progress;  // (done, total)
};

/// Prints the table (or JSON); returns 1 when a shown frame differs from the rendered one.
/// Throws lucent::Error when no headless OpenGL context can be made.
int run_present_bench(const PresentBenchOptions& options);

}  // namespace lucent::bench

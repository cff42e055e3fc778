// `lucent render`: runs a sample and writes its image.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "camera_flags.h"

namespace lucent::cli {

/// The render options as typed; parsed and checked by run_render.
struct RenderArgs {
    std::string sample = "whitted";
    std::string size = "1024x1024";
    std::string out = "lucent.png";
    std::string backend = "auto";
    std::string devices;  // --devices 0,1: launches spread over several devices
    std::string scene;
    std::vector<std::string> sets;
    unsigned threads = 0;
    bool verbose = false;
    unsigned repeat = 1;    // launches; >1 reports the median launch time
    unsigned spp = 0;       // samples per pixel of progressive samples; 0 = the sample's default
    std::string jit_check;  // e.g. "sm_90": also compile the CUDA megakernel (no GPU needed)
    int camera = -1;                 // --camera N: the scene file's camera N; -1 = its first
    CameraFlags camera_flags;        // --eye --look --up --fov, over the scene's camera
    bool quiet = false;  // no header, progress or timings: only errors
    bool json = false;   // the settings and timings as one JSON object on stdout
    std::string aov;     // --aov albedo,normal,...: G-buffer layers in the EXR
    bool aov_given = false;  // --aov appeared (so that an empty list is an error)
    bool denoise = false;  // --denoise: the edge-avoiding à-trous filter
    unsigned denoise_passes = 0;  // --denoise-passes: 0 = DenoiseOptions' default
};

/// Adds the `render` subcommand to `app`; its options fill `args`.
CLI::App* add_render_command(CLI::App& app, RenderArgs& args);
/// Runs a parsed `render`; returns the exit code. Throws UsageError, lucent::Error.
int run_render(const RenderArgs& args);

}  // namespace lucent::cli

// `lucent view`: a window showing a sample rendered interactively (apps/viewer/).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "camera_flags.h"

namespace lucent::cli {

/// The view options as typed; parsed and checked by run_view.
struct ViewArgs {
    std::string sample = "whitted";
    std::string size = "800x600";
    std::string backend = "auto";
    std::string devices;
    std::string scene;
    int camera = -1;  // --camera N: the scene file's camera N to start from; -1 = its first
    std::vector<std::string> sets;
    unsigned threads = 0;
    unsigned spp = 0;        // progressive samples stop refining here; 0 = never
    unsigned frames = 0;     // >0: render this many frames, then exit (headless checks)
    std::string screenshot;  // with --frames: save what the window shows here
    bool no_panel = false;   // hide the ImGui panel (screenshots of the image alone)
    float ui_scale = 0;      // the panel's scale; 0 = the window's content scale
    std::string denoiser = "off";
    CameraFlags camera_flags;  // --eye --look --up --fov: the camera to start from
    bool verbose = false;
    bool fit_window = false;  // render at the window's size as it is resized
    double soak = 0;          // >0: the soak, this many seconds (apps/viewer/soak.h)
};

/// Adds the `view` subcommand to `app`; its options fill `args`.
CLI::App* add_view_command(CLI::App& app, ViewArgs& args);
/// Runs a parsed `view`; returns the exit code. Throws UsageError, lucent::Error.
int run_view(const ViewArgs& args);

}  // namespace lucent::cli

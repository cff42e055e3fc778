// The path tracer's scene as a building block: the sample's render and its interactive
// session (`lucent view`) build the same scene and differ only in their camera program.
#pragma once

#include <memory>
#include <string>

#include "samples/sample.h"

namespace lucent::samples {

/// The sample's --set options, checked.
struct PathOptions {
    int max_depth = 8, rr_depth = 3, nee = 1;
    float environment = 0, exposure = 1;
    int reinhard = 0, seed = 0;
};

/// Reads and checks the options; SettingsError on bad input.
PathOptions read_path_options(const RenderSettings& settings);

/// Sets the options that are variables of a camera program (pt_camera or pt_view_camera).
void set_path_camera_options(Program& camera, const PathOptions& options);

/// What build_path_scene made that the camera program needs.
struct PathScene {
    scene::Camera camera;                   // the scene's own camera
    std::shared_ptr<Buffer> accum, output;  // width x height float4
    std::shared_ptr<Program> miss;          // holds the "environment" variable
    std::string note;                       // "cornell, 32 triangles"
};

/// Builds the scene of settings.scene (default: cornell) into `ctx`, everything but the
/// ray-generation program.
PathScene build_path_scene(Context& ctx, const RenderSettings& settings,
                           const PathOptions& options);

/// The progressive interactive session: the camera from a buffer (pt_view_camera), one
/// sample per pixel per frame, accumulated while the camera rests.
std::unique_ptr<InteractiveSession> open_pathtracer_session(const RenderSettings& settings);

}  // namespace lucent::samples

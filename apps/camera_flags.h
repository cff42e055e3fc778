// The camera flags `lucent render` and `lucent view` share (--eye --look --up --fov): their
// options, their parsing, and a camera written back as those flags so that parsing them
// gives the same floats (the viewer's "copy as flags").
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "samples/camera_override.h"
#include "scene/scene.h"

namespace lucent::cli {

struct CameraFlags {
    std::string eye, look, up, fov;  // each optional: the rest from the scene
};

/// Adds --eye --look --up --fov to `cmd`.
void add_camera_flags(CLI::App* cmd, CameraFlags& flags);
/// The given flags, checked (UsageError naming the flag and the expected form).
samples::CameraOverride parse_camera_flags(const CameraFlags& flags);

/// "--eye 1,2,3 --look 0,0,0 --up 0,1,0 --fov 45", each number the shortest text that
/// reads back as the same float.
std::string camera_flags(const scene::Camera& camera);

}  // namespace lucent::cli

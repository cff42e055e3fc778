#include "camera_flags.h"

#include <charconv>

#include "cli_parse.h"

namespace lucent::cli {
namespace {

/// The shortest text that reads back as exactly `v` (std::to_chars' guarantee).
std::string number(float v) {
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, v).ptr;
    return std::string(text, end);
}

std::string vec(float3 v) {
    return number(v.x) + "," + number(v.y) + "," + number(v.z);
}

}  // namespace

void add_camera_flags(CLI::App* cmd, CameraFlags& flags) {
    cmd->add_option("--eye", flags.eye, "Camera position, over the scene's")->type_name("X,Y,Z");
    cmd->add_option("--look", flags.look, "Point the camera looks at, over the scene's")
        ->type_name("X,Y,Z");
    cmd->add_option("--up", flags.up, "Camera up direction, over the scene's")->type_name("X,Y,Z");
    cmd->add_option("--fov", flags.fov,
                    "Vertical field of view in degrees, (0, 180), over the scene's")
        ->type_name("DEG");
}

samples::CameraOverride parse_camera_flags(const CameraFlags& flags) {
    samples::CameraOverride camera;
    if (!flags.eye.empty()) camera.eye = parse_vec3("--eye", flags.eye);
    if (!flags.look.empty()) camera.look = parse_vec3("--look", flags.look);
    if (!flags.up.empty()) camera.up = parse_vec3("--up", flags.up);
    if (!flags.fov.empty()) camera.fov_degrees = parse_float("--fov", flags.fov, 0, 180, true);
    return camera;
}

std::string camera_flags(const scene::Camera& camera) {
    return "--eye " + vec(camera.eye) + " --look " + vec(camera.look) + " --up " + vec(camera.up) +
           " --fov " + number(camera.fov_degrees);
}

}  // namespace lucent::cli

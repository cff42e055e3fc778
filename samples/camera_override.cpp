#include "samples/camera_override.h"

#include <cmath>
#include <cstdio>

#include "samples/settings_error.h"

namespace lucent::samples {

namespace {

std::string text(float3 v) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%g,%g,%g", double(v.x), double(v.y), double(v.z));
    return buf;
}

std::string number(float f) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", double(f));
    return buf;
}

bool finite(float3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

scene::Camera CameraOverride::applied_to(scene::Camera camera) const {
    if (eye) camera.eye = *eye;
    if (look) camera.look = *look;
    if (up) camera.up = *up;
    if (fov_degrees) camera.fov_degrees = *fov_degrees;
    for (auto [name, value] : {std::pair{"eye", camera.eye}, std::pair{"look", camera.look},
                               std::pair{"up", camera.up}})
        if (!finite(value))
            throw SettingsError(std::string("camera: ") + name + " " + text(value) +
                                " is not a point of finite coordinates");
    if (!(camera.fov_degrees > 0.0f && camera.fov_degrees < 180.0f))
        throw SettingsError("camera: fov " + number(camera.fov_degrees) +
                            " degrees; the vertical field of view must be in (0, 180) (--fov)");
    const float3 view = camera.look - camera.eye;
    const float distance = length(view);
    if (!(distance > 0.0f))
        throw SettingsError("camera: eye and look are the same point (" + text(camera.eye) +
                            "); the camera looks from eye towards look, so move one of them "
                            "(--eye, --look)");
    if (scene::up_along_view(camera))
        throw SettingsError("camera: up " + text(camera.up) +
                            " is zero or along the view direction from eye " + text(camera.eye) +
                            " to look " + text(camera.look) +
                            "; give an up at an angle to it (--up, e.g. 0,1,0 for a horizontal "
                            "view)");
    return camera;
}

}  // namespace lucent::samples

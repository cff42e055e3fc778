#include "scene/camera_controller.h"

#include <algorithm>
#include <cmath>

namespace lucent::scene {
namespace {

/// v turned by `angle` radians about the unit axis k (Rodrigues' rotation formula).
float3 rotate(float3 v, float3 k, float angle) {
    const float c = std::cos(angle), s = std::sin(angle);
    return v * c + cross(k, v) * s + k * (dot(k, v) * (1.0f - c));
}

}  // namespace

CameraController::CameraController(const Camera& start) : m_start(start), m_camera(start) {
    m_start.up = normalize(start.up);
    m_camera.up = m_start.up;
}

float CameraController::distance() const {
    return length(m_camera.eye - m_camera.look);
}

void CameraController::orbit(float yaw, float pitch) {
    const float3 up = m_camera.up;
    float3 offset = rotate(m_camera.eye - m_camera.look, up, -yaw);
    // Keep the angle between the offset and the up axis within [kPole, pi - kPole]: at a pole
    // the view's right vector, cross(forward, up), is undefined.
    constexpr float kPole = 0.02f;
    const float r = length(offset);
    const float polar = std::acos(std::clamp(dot(offset, up) / r, -1.0f, 1.0f));
    const float target = std::clamp(polar - pitch, kPole, 3.14159265f - kPole);
    const float3 axis = normalize(cross(up, offset));
    offset = rotate(offset, axis, target - polar);
    m_camera.eye = m_camera.look + offset;
}

void CameraController::pan(float x, float y) {
    const float3 forward = normalize(m_camera.look - m_camera.eye);
    const float3 right = normalize(cross(forward, m_camera.up));
    const float3 up = cross(right, forward);
    const float height =
        2.0f * distance() * std::tan(0.5f * m_camera.fov_degrees * 3.14159265f / 180.0f);
    // The scene follows the cursor: the camera moves the other way.
    const float3 move = (right * -x + up * -y) * height;
    m_camera.eye += move;
    m_camera.look += move;
}

void CameraController::zoom(float factor) {
    const float3 offset = m_camera.eye - m_camera.look;
    const float d = std::max(length(offset) * factor, closest_distance());
    m_camera.eye = m_camera.look + normalize(offset) * d;
}

float CameraController::closest_distance() const {
    // Relative to the start, so a scene modelled in micrometres zooms as one in metres (an
    // absolute floor stopped a scene 5e-4 wide at a fifth of its starting distance). And 16
    // float spacings of the target's largest coordinate at least: the eye, rounded to the
    // spacing, stays apart from the target with its direction within a few degrees, however
    // far the scene lies from the origin.
    const float start = length(m_start.eye - m_start.look);
    const float largest = std::max({std::fabs(m_camera.look.x), std::fabs(m_camera.look.y),
                                    std::fabs(m_camera.look.z)});
    const float spacing = std::nextafter(largest, INFINITY) - largest;
    return std::max(kClosestFraction * start, 16.0f * spacing);
}

void CameraController::fly(float forward, float right, float up) {
    const float3 f = normalize(m_camera.look - m_camera.eye);
    const float3 r = normalize(cross(f, m_camera.up));
    const float3 move = f * forward + r * right + m_camera.up * up;
    m_camera.eye += move;
    m_camera.look += move;
}

}  // namespace lucent::scene

#include "input.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>

#include "key_bindings.h"

namespace lucent::viewer {
namespace {

constexpr float kOrbitRadiansPerPixel = 0.005f;
constexpr float kZoomPerWheelStep = 0.9f;
constexpr float kFlyDistancesPerSecond = 0.8f;  // of the distance to the target
constexpr float kShiftSpeedUp = 4.0f;

}  // namespace

Input::Input(GLFWwindow* window) : m_window(window) {
    glfwSetWindowUserPointer(window, this);
    glfwSetScrollCallback(window, &Input::on_scroll);
    glfwSetKeyCallback(window, &Input::on_key);
    glfwGetCursorPos(window, &m_cursor_x, &m_cursor_y);
}

void Input::on_scroll(GLFWwindow* window, double, double y) {
    static_cast<Input*>(glfwGetWindowUserPointer(window))->m_scroll += y;
}

void Input::on_key(GLFWwindow* window, int key, int, int action, int) {
    if (action == GLFW_PRESS)
        static_cast<Input*>(glfwGetWindowUserPointer(window))->m_presses.push_back(key);
}

std::vector<int> Input::take_presses() {
    std::vector<int> presses;
    presses.swap(m_presses);
    return presses;
}

bool Input::move_camera(scene::CameraController& camera, float dt, bool ui_mouse, bool ui_keys) {
    double x = 0, y = 0;
    glfwGetCursorPos(m_window, &x, &y);
    const float dx = float(x - m_cursor_x), dy = float(y - m_cursor_y);
    m_cursor_x = x;
    m_cursor_y = y;
    const double scroll = m_scroll;
    m_scroll = 0;
    int width = 1, height = 1;
    glfwGetWindowSize(m_window, &width, &height);
    bool moved = false;
    if (!ui_mouse) {
        if (glfwGetMouseButton(m_window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS &&
            (dx != 0 || dy != 0)) {
            camera.orbit(dx * kOrbitRadiansPerPixel, dy * kOrbitRadiansPerPixel);
            moved = true;
        } else if ((glfwGetMouseButton(m_window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS ||
                    glfwGetMouseButton(m_window, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS) &&
                   (dx != 0 || dy != 0)) {
            // Window y grows downwards, the camera's up upwards.
            camera.pan(dx / float(std::max(height, 1)), -dy / float(std::max(height, 1)));
            moved = true;
        }
        if (scroll != 0) {
            camera.zoom(std::pow(kZoomPerWheelStep, float(scroll)));
            moved = true;
        }
    }
    if (!ui_keys) {
        auto held = [&](int key) { return glfwGetKey(m_window, key) == GLFW_PRESS ? 1.0f : 0.0f; };
        // The fly keys from the bindings table (key_bindings.cpp), which F1 lists.
        auto flying = [&](KeyAction a) { return held(key_of(a)); };
        const float forward = flying(KeyAction::kFlyForward) - flying(KeyAction::kFlyBack);
        const float right = flying(KeyAction::kFlyRight) - flying(KeyAction::kFlyLeft);
        const float up = flying(KeyAction::kFlyUp) - flying(KeyAction::kFlyDown);
        if (forward != 0 || right != 0 || up != 0) {
            const bool fast = held(GLFW_KEY_LEFT_SHIFT) + held(GLFW_KEY_RIGHT_SHIFT) > 0;
            // Speed in proportion to the distance to the target: the same feel at any scale.
            const float step =
                camera.distance() * kFlyDistancesPerSecond * dt * (fast ? kShiftSpeedUp : 1.0f);
            camera.fly(forward * step, right * step, up * step);
            moved = true;
        }
    }
    return moved;
}

}  // namespace lucent::viewer

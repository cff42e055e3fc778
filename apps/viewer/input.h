// Mouse and keyboard for the viewer: camera moves (orbit, pan, zoom, fly) applied to a
// CameraController, and the key presses the viewer acts on.
#pragma once

#include <vector>

#include "scene/camera_controller.h"

struct GLFWwindow;

namespace lucent::viewer {

class Input {
  public:
    /// Installs the scroll and key callbacks; call before ImGui's GLFW backend, which chains
    /// to them.
    explicit Input(GLFWwindow* window);

    /// Applies the mouse drags, wheel and held fly keys since the last call (`dt` seconds
    /// ago) to `camera`; returns true when it moved. Skips the mouse or the keys while ImGui
    /// uses them.
    bool move_camera(scene::CameraController& camera, float dt, bool ui_mouse, bool ui_keys);
    /// Keys pressed since the last call (GLFW_KEY_*), in order.
    std::vector<int> take_presses();

  private:
    static void on_scroll(GLFWwindow* window, double x, double y);
    static void on_key(GLFWwindow* window, int key, int scancode, int action, int mods);

    GLFWwindow* m_window;
    double m_cursor_x = 0, m_cursor_y = 0;
    double m_scroll = 0;
    std::vector<int> m_presses;
};

}  // namespace lucent::viewer

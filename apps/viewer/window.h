// The viewer's window: GLFW with an OpenGL 3.3 core context, and Dear ImGui on it.
#pragma once

#include <string>

struct GLFWwindow;

namespace lucent::viewer {

class Window {
  public:
    /// Opens a window whose drawable area is width x height where the screen allows (always
    /// with `exact`, for screenshots); throws lucent::Error saying why it cannot.
    Window(const std::string& title, int width, int height, bool exact);
    ~Window();
    Window(const Window&) = delete;
    Window& operator=(const Window&) = delete;

    GLFWwindow* handle() const { return m_window; }
    /// Sets up ImGui's GLFW and OpenGL3 backends (after the app's own GLFW callbacks, which
    /// ImGui then chains to), its text and controls scaled by `scale` (0: the window's
    /// content scale, which the desktop sets for high-DPI screens).
    void start_ui(float scale);
    /// The scale start_ui chose.
    float ui_scale() const { return m_ui_scale; }
    bool should_close() const;
    void close();
    /// Waits up to `seconds` for input, so an idle viewer does not spin a core.
    void wait_events(double seconds);
    void begin_ui_frame();
    void end_ui_frame();  // draws the ImGui lists
    void swap();
    void framebuffer_size(int& width, int& height) const;
    /// Resizes the window's drawable area, as a user dragging its border would (the soak).
    void set_size(int width, int height);

  private:
    GLFWwindow* m_window = nullptr;
    bool m_ui = false;
    float m_ui_scale = 1;
};

}  // namespace lucent::viewer

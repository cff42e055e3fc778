#include "window.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>

#include "lucent/error.h"

namespace lucent::viewer {
namespace {

std::string g_glfw_error;  // GLFW reports errors through a callback, not return values

void on_glfw_error(int, const char* description) {
    g_glfw_error = description;
}

}  // namespace

Window::Window(const std::string& title, int width, int height, bool exact) {
    glfwSetErrorCallback(&on_glfw_error);
    if (!glfwInit())
        throw Error("viewer: cannot open a window (" + g_glfw_error +
                    "); is there a display? Headless, run it under xvfb-run -a -s '-screen 0 "
                    "1280x1024x24' lucent view ...");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    if (!exact) {
        // A large render is shown scaled down in a window that fits the screen.
        if (const GLFWvidmode* mode = glfwGetVideoMode(glfwGetPrimaryMonitor())) {
            const float fit = std::min({1.0f, 0.9f * float(mode->width) / float(width),
                                        0.9f * float(mode->height) / float(height)});
            width = std::max(1, int(float(width) * fit));
            height = std::max(1, int(float(height) * fit));
        }
    }
    m_window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (!m_window) {
        const std::string why = g_glfw_error;
        glfwTerminate();
        throw Error("viewer: cannot create an OpenGL 3.3 window (" + why + ")");
    }
    glfwMakeContextCurrent(m_window);
    glfwSwapInterval(1);
}

Window::~Window() {
    if (m_ui) {
        ImGui_ImplOpenGL3_Shutdown();
        ImGui_ImplGlfw_Shutdown();
        ImGui::DestroyContext();
    }
    glfwDestroyWindow(m_window);
    glfwTerminate();
}

void Window::start_ui(float scale) {
    if (scale <= 0) {
        float x = 1, y = 1;
        glfwGetWindowContentScale(m_window, &x, &y);
        scale = std::clamp(std::max(x, y), 0.5f, 8.0f);
    }
    m_ui_scale = scale;
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini left in the user's directory
    ImGui::StyleColorsDark();
    // The default font is a 13-pixel bitmap: scaled, it stays legible, if soft.
    ImGui::GetStyle().ScaleAllSizes(scale);
    ImGui::GetIO().FontGlobalScale = scale;
    ImGui_ImplGlfw_InitForOpenGL(m_window, /*install_callbacks=*/true);
    ImGui_ImplOpenGL3_Init("#version 330 core");
    m_ui = true;
}

bool Window::should_close() const {
    return glfwWindowShouldClose(m_window);
}
void Window::close() {
    glfwSetWindowShouldClose(m_window, GLFW_TRUE);
}
void Window::wait_events(double seconds) {
    glfwWaitEventsTimeout(seconds);
}

void Window::begin_ui_frame() {
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
}

void Window::end_ui_frame() {
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

void Window::swap() {
    glfwSwapBuffers(m_window);
}

void Window::framebuffer_size(int& width, int& height) const {
    glfwGetFramebufferSize(m_window, &width, &height);
}

void Window::set_size(int width, int height) {
    glfwSetWindowSize(m_window, width, height);
}

}  // namespace lucent::viewer

// An OpenGL 3.3 core context without a window or display server (EGL on a GPU device, or
// Mesa's software device), drawing into a framebuffer object of a fixed size. For
// `lucent bench present`, which times the viewer's presentation path where no window
// can open (a GPU server, CI).
#pragma once

#include <string>

#include "present/gl.h"

namespace lucent::viewer {

class HeadlessGl {
  public:
    /// Opens a context current on this thread and binds a width x height RGBA8 framebuffer.
    /// `prefer_cuda`: take a device the CUDA driver drives (EGL_NV_device_cuda) when there
    /// is one, so CUDA–OpenGL interop can work. Throws lucent::Error saying what is missing.
    HeadlessGl(int width, int height, bool prefer_cuda);
    ~HeadlessGl();
    HeadlessGl(const HeadlessGl&) = delete;
    HeadlessGl& operator=(const HeadlessGl&) = delete;

    /// "NVIDIA H200/PCIe/SSE2" or "llvmpipe (LLVM 15.0.6, 256 bits)": GL_RENDERER.
    std::string renderer() const;

  private:
    void* m_display = nullptr;  // EGLDisplay
    void* m_context = nullptr;  // EGLContext
    GLuint m_framebuffer = 0, m_color = 0;
};

}  // namespace lucent::viewer

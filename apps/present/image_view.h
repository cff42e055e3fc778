// Shows a rendered image in the current OpenGL framebuffer, drawn as a quad that keeps the
// image's aspect ratio. The fragment shader reads the RGBA8 pixels straight from a buffer
// object (a buffer texture), so a frame costs one copy into that buffer and nothing more:
// GPU to GPU through CUDA–OpenGL interop for frames rendered on a GPU (lucent/display.h),
// from host memory otherwise. (A 2D texture filled from a pixel-buffer object costs a
// second copy that measured 0.8 ms at 1920x1080 on an H200.)
#pragma once

#include <memory>
#include <string>

#include "lucent/display.h"
#include "present/gl.h"

namespace lucent::viewer {

class ImageView {
  public:
    ImageView();  // needs a current OpenGL 3.3 context
    ~ImageView();
    ImageView(const ImageView&) = delete;
    ImageView& operator=(const ImageView&) = delete;

    /// Shows a display frame: through CUDA–OpenGL interop when it is on a GPU and interop
    /// works here, else (and for good once interop failed, the reason in presentation())
    /// uploaded from host memory.
    void show(const DisplayFrame& frame);
    /// Shows 8-bit RGBA pixels (row 0 at the top) from host memory.
    void upload(const unsigned char* rgba, unsigned width, unsigned height);
    /// Never use interop (the host path, for comparisons).
    void disable_interop(const std::string& why);
    /// How the last frame reached the window: "CUDA-OpenGL interop" or "host upload ...".
    const std::string& presentation() const { return m_presentation; }

    /// Draws the image over a framebuffer of this size, centred, aspect kept; pixel for
    /// pixel when the sizes match (nearest pixel otherwise).
    void draw(int framebuffer_width, int framebuffer_height);
    bool empty() const { return m_width == 0; }

  private:
    /// Points the buffer texture at `buffer`, which holds width x height pixels.
    void use_buffer(GLuint buffer, unsigned width, unsigned height);
    bool show_through_interop(const DisplayFrame& frame);

    GLuint m_program = 0, m_vao = 0, m_texture = 0, m_upload_buffer = 0, m_interop_buffer = 0;
    GLint m_scale = -1, m_size = -1;
    GLint m_max_texels = 0;  // GL_MAX_TEXTURE_BUFFER_SIZE
    unsigned m_width = 0, m_height = 0;
    std::unique_ptr<GlPixelBuffer> m_interop;  // registered with CUDA at the first GPU frame
    size_t m_interop_bytes = 0;
    bool m_interop_failed = false;
    std::string m_presentation = "none yet";
};

}  // namespace lucent::viewer

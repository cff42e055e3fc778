// Shows a rendered image in the current OpenGL framebuffer: a texture drawn as a quad that
// keeps the image's aspect ratio. Frames rendered on a GPU reach the texture GPU to GPU
// (CUDA–OpenGL interop straight into the texture, lucent/display.h); host frames are
// uploaded through a pixel-buffer object.
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
    /// Copies 8-bit RGBA pixels (row 0 at the top) into the texture.
    void upload(const unsigned char* rgba, unsigned width, unsigned height);
    /// Never use interop (the host path, for comparisons).
    void disable_interop(const std::string& why);
    /// How the last frame reached the texture: "CUDA-OpenGL interop" or "host upload ...".
    const std::string& presentation() const { return m_presentation; }

    /// Draws the image over a framebuffer of this size, centred, aspect kept; pixel for
    /// pixel when the sizes match.
    void draw(int framebuffer_width, int framebuffer_height);
    bool empty() const { return m_width == 0; }

  private:
    /// Sizes the texture for width x height (contents undefined until written).
    void size_texture(unsigned width, unsigned height);
    bool show_through_interop(const DisplayFrame& frame);

    GLuint m_program = 0, m_vao = 0, m_texture = 0, m_upload_pbo = 0;
    GLint m_scale = -1;
    unsigned m_width = 0, m_height = 0;
    std::unique_ptr<GlTexture> m_interop;  // the texture, registered at the first GPU frame
    bool m_interop_failed = false;
    std::string m_presentation = "none yet";
};

}  // namespace lucent::viewer

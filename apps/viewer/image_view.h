// Shows the rendered image in the window: uploaded through a pixel-buffer object into a
// texture, drawn as a quad that keeps the image's aspect ratio.
#pragma once

#include "gl.h"

namespace lucent::viewer {

class ImageView {
  public:
    ImageView();  // needs a current OpenGL 3.3 context
    ~ImageView();
    ImageView(const ImageView&) = delete;
    ImageView& operator=(const ImageView&) = delete;

    /// Copies 8-bit RGB pixels (row 0 at the top) into the texture.
    void upload(const unsigned char* rgb, unsigned width, unsigned height);
    /// Draws the image over a framebuffer of this size, centred, aspect kept; pixel for
    /// pixel when the sizes match.
    void draw(int framebuffer_width, int framebuffer_height);
    bool empty() const { return m_width == 0; }

  private:
    GLuint m_program = 0, m_vao = 0, m_texture = 0, m_pbo = 0;
    GLint m_scale = -1;
    unsigned m_width = 0, m_height = 0;
};

}  // namespace lucent::viewer

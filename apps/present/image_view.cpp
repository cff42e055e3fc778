#include "present/image_view.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "lucent/error.h"

namespace lucent::viewer {
namespace {

// A quad from gl_VertexID alone (no vertex buffer); v flipped because row 0 is the top.
constexpr const char* kVertexShader = R"(#version 330 core
uniform vec2 scale;
out vec2 uv;
void main() {
    vec2 p = vec2(float(gl_VertexID & 1) * 2.0 - 1.0, float(gl_VertexID >> 1) * 2.0 - 1.0);
    uv = vec2(0.5 * p.x + 0.5, 0.5 - 0.5 * p.y);
    gl_Position = vec4(p * scale, 0.0, 1.0);
}
)";

// The texels are sRGB already (the conversion `lucent render` uses for PNGs).
constexpr const char* kFragmentShader = R"(#version 330 core
uniform sampler2D image;
in vec2 uv;
out vec4 color;
void main() { color = vec4(texture(image, uv).rgb, 1.0); }
)";

GLuint compile(GLenum kind, const char* source) {
    const GLuint shader = glCreateShader(kind);
    glShaderSource(shader, 1, &source, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[1024] = {};
        glGetShaderInfoLog(shader, sizeof log, nullptr, log);
        throw Error(std::string("viewer: the OpenGL driver rejected a shader: ") + log);
    }
    return shader;
}

}  // namespace

ImageView::ImageView() {
    const GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader);
    const GLuint fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
    m_program = glCreateProgram();
    glAttachShader(m_program, vs);
    glAttachShader(m_program, fs);
    glLinkProgram(m_program);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(m_program, GL_LINK_STATUS, &ok);
    if (!ok) throw Error("viewer: the OpenGL driver could not link the image shader");
    m_scale = glGetUniformLocation(m_program, "scale");
    glGenVertexArrays(1, &m_vao);  // core profile: a draw needs one bound, even empty
    glGenTextures(1, &m_texture);
    glBindTexture(GL_TEXTURE_2D, m_texture);
    // Nearest: at 1:1 every pixel is shown as rendered (the headless check compares them).
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glGenBuffers(1, &m_upload_pbo);
}

ImageView::~ImageView() {
    m_interop.reset();  // unregistered from CUDA before the texture goes
    glDeleteBuffers(1, &m_upload_pbo);
    glDeleteTextures(1, &m_texture);
    glDeleteVertexArrays(1, &m_vao);
    glDeleteProgram(m_program);
}

void ImageView::size_texture(unsigned width, unsigned height) {
    if (width == m_width && height == m_height) return;
    if (m_interop) m_interop->release();  // a registered texture must not be re-specified
    glBindTexture(GL_TEXTURE_2D, m_texture);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, GLsizei(width), GLsizei(height), 0, GL_RGBA,
                 GL_UNSIGNED_BYTE, nullptr);
    m_width = width;
    m_height = height;
}

void ImageView::upload(const unsigned char* rgba, unsigned width, unsigned height) {
    size_texture(width, height);
    const GLsizeiptr bytes = GLsizeiptr(width) * height * 4;
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, m_upload_pbo);
    // Orphan the old storage so the driver need not wait for the previous upload to finish.
    glBufferData(GL_PIXEL_UNPACK_BUFFER, bytes, nullptr, GL_STREAM_DRAW);
    void* mapped = glMapBufferRange(GL_PIXEL_UNPACK_BUFFER, 0, bytes,
                                    GL_MAP_WRITE_BIT | GL_MAP_INVALIDATE_BUFFER_BIT);
    if (mapped) {
        std::memcpy(mapped, rgba, size_t(bytes));
        glUnmapBuffer(GL_PIXEL_UNPACK_BUFFER);
    }
    glBindTexture(GL_TEXTURE_2D, m_texture);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    // From the pixel-buffer object (the pointer 0 stands for its start), or straight from
    // memory on a driver that cannot map.
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, GLsizei(width), GLsizei(height), GL_RGBA,
                    GL_UNSIGNED_BYTE, mapped ? nullptr : rgba);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
}

void ImageView::disable_interop(const std::string& why) {
    m_interop.reset();
    m_interop_failed = true;
    m_presentation = "host upload (" + why + ")";
}

bool ImageView::show_through_interop(const DisplayFrame& frame) {
    try {
        size_texture(frame.width(), frame.height());
        if (!m_interop) m_interop = std::make_unique<GlTexture>(m_texture);
        m_interop->copy_from(frame);  // GPU to GPU; done when it returns
    } catch (const std::exception& e) {
        disable_interop(e.what());
        return false;
    }
    m_presentation = "CUDA-OpenGL interop";
    return true;
}

void ImageView::show(const DisplayFrame& frame) {
    if (frame.on_device() && !m_interop_failed && show_through_interop(frame)) return;
    const std::vector<unsigned char> rgba = frame.rgba();
    upload(rgba.data(), frame.width(), frame.height());
    if (!m_interop_failed) m_presentation = "host upload";
}

void ImageView::draw(int framebuffer_width, int framebuffer_height) {
    if (empty() || framebuffer_width <= 0 || framebuffer_height <= 0) return;
    const float image_aspect = float(m_width) / float(m_height);
    const float window_aspect = float(framebuffer_width) / float(framebuffer_height);
    const float sx = std::min(1.0f, image_aspect / window_aspect);
    const float sy = std::min(1.0f, window_aspect / image_aspect);
    glViewport(0, 0, framebuffer_width, framebuffer_height);
    glUseProgram(m_program);
    glUniform2f(m_scale, sx, sy);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, m_texture);
    glBindVertexArray(m_vao);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    glBindVertexArray(0);
}

}  // namespace lucent::viewer

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

// The pixels are sRGB already (the encoding `lucent render` uses for PNGs), row 0 first;
// the nearest one to uv, as GL_NEAREST would pick it.
constexpr const char* kFragmentShader = R"(#version 330 core
uniform samplerBuffer image;
uniform ivec2 size;
in vec2 uv;
out vec4 color;
void main() {
    ivec2 p = clamp(ivec2(uv * vec2(size)), ivec2(0), size - 1);
    color = vec4(texelFetch(image, p.y * size.x + p.x).rgb, 1.0);
}
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
    m_size = glGetUniformLocation(m_program, "size");
    glGenVertexArrays(1, &m_vao);  // core profile: a draw needs one bound, even empty
    glGenTextures(1, &m_texture);
    glGenBuffers(1, &m_upload_buffer);
    glGenBuffers(1, &m_interop_buffer);
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &m_max_texels);
}

ImageView::~ImageView() {
    m_interop.reset();  // unregistered from CUDA before the buffer goes
    GLuint buffers[] = {m_upload_buffer, m_interop_buffer};
    glDeleteBuffers(2, buffers);
    glDeleteTextures(1, &m_texture);
    glDeleteVertexArrays(1, &m_vao);
    glDeleteProgram(m_program);
}

void ImageView::use_buffer(GLuint buffer, unsigned width, unsigned height) {
    glBindTexture(GL_TEXTURE_BUFFER, m_texture);
    glTexBuffer(GL_TEXTURE_BUFFER, GL_RGBA8, buffer);
    glBindTexture(GL_TEXTURE_BUFFER, 0);
    m_width = width;
    m_height = height;
}

void ImageView::upload(const unsigned char* rgba, unsigned width, unsigned height) {
    if (double(width) * height > double(m_max_texels))
        throw Error("viewer: a " + std::to_string(width) + "x" + std::to_string(height) +
                    " image is more than this OpenGL driver's " + std::to_string(m_max_texels) +
                    " texels in a buffer texture; render a smaller --size");
    const GLsizeiptr bytes = GLsizeiptr(width) * height * 4;
    glBindBuffer(GL_TEXTURE_BUFFER, m_upload_buffer);
    // New storage each time (orphaning): the driver need not wait for the last draw's reads.
    glBufferData(GL_TEXTURE_BUFFER, bytes, rgba, GL_STREAM_DRAW);
    glBindBuffer(GL_TEXTURE_BUFFER, 0);
    use_buffer(m_upload_buffer, width, height);
}

void ImageView::disable_interop(const std::string& why) {
    m_interop.reset();
    m_interop_failed = true;
    m_presentation = "host upload (" + why + ")";
}

bool ImageView::show_through_interop(const DisplayFrame& frame) {
    try {
        if (double(frame.width()) * frame.height() > double(m_max_texels))
            throw Error("the frame is larger than a buffer texture may be");
        if (!m_interop) m_interop = std::make_unique<GlPixelBuffer>(m_interop_buffer);
        if (m_interop_bytes != frame.bytes()) {
            m_interop->release();  // a registered buffer must not change its storage
            glBindBuffer(GL_TEXTURE_BUFFER, m_interop_buffer);
            glBufferData(GL_TEXTURE_BUFFER, GLsizeiptr(frame.bytes()), nullptr, GL_DYNAMIC_DRAW);
            glBindBuffer(GL_TEXTURE_BUFFER, 0);
            m_interop_bytes = frame.bytes();
        }
        m_interop->copy_from(frame);  // GPU to GPU; done when it returns
    } catch (const std::exception& e) {
        disable_interop(e.what());
        return false;
    }
    use_buffer(m_interop_buffer, frame.width(), frame.height());
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
    glUniform2i(m_size, GLint(m_width), GLint(m_height));
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_BUFFER, m_texture);
    glBindVertexArray(m_vao);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    glBindVertexArray(0);
}

}  // namespace lucent::viewer

#include "present/headless_gl.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <vector>

#include "lucent/error.h"

namespace lucent::viewer {
namespace {

template <class Fn>
Fn egl_function(const char* name) {
    auto fn = reinterpret_cast<Fn>(eglGetProcAddress(name));
    if (!fn)
        throw Error(std::string("headless OpenGL: EGL lacks ") + name +
                    " (EGL_EXT_device_enumeration); install an EGL 1.5 driver (libegl1)");
    return fn;
}

bool has_word(const char* list, const char* word) {
    if (!list) return false;
    const size_t n = std::strlen(word);
    for (const char* p = std::strstr(list, word); p; p = std::strstr(p + 1, word))
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
    return false;
}

/// An initialised display on one of EGL's devices, the CUDA-capable ones first when asked.
EGLDisplay open_device_display(bool prefer_cuda) {
    const auto query_devices = egl_function<PFNEGLQUERYDEVICESEXTPROC>("eglQueryDevicesEXT");
    const auto query_string =
        egl_function<PFNEGLQUERYDEVICESTRINGEXTPROC>("eglQueryDeviceStringEXT");
    const auto platform_display =
        egl_function<PFNEGLGETPLATFORMDISPLAYEXTPROC>("eglGetPlatformDisplayEXT");
    EGLint count = 0;
    EGLDeviceEXT devices[16];
    if (!query_devices(16, devices, &count) || count == 0)
        throw Error("headless OpenGL: EGL lists no device (no GPU driver and no Mesa)");
    std::vector<EGLDeviceEXT> order;
    for (int pass = 0; pass < 2; ++pass)
        for (EGLint i = 0; i < count; ++i) {
            const bool cuda = has_word(query_string(devices[i], EGL_EXTENSIONS), "EGL_NV_device_cuda");
            if ((pass == 0) == (cuda == prefer_cuda)) order.push_back(devices[i]);
        }
    for (EGLDeviceEXT device : order) {
        EGLDisplay display = platform_display(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
        EGLint major = 0, minor = 0;
        if (display != EGL_NO_DISPLAY && eglInitialize(display, &major, &minor)) return display;
    }
    throw Error("headless OpenGL: no EGL device could be initialised");
}

}  // namespace

HeadlessGl::HeadlessGl(int width, int height, bool prefer_cuda) {
    EGLDisplay display = open_device_display(prefer_cuda);
    m_display = display;
    // EGL_SURFACE_TYPE defaults to windows, which a device display has none of.
    const EGLint config_attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE,
                                        EGL_PBUFFER_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint configs = 0;
    if (!eglBindAPI(EGL_OPENGL_API) ||
        !eglChooseConfig(display, config_attributes, &config, 1, &configs) || configs == 0)
        throw Error("headless OpenGL: the EGL device offers no desktop OpenGL configuration");
    const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3,
                                         EGL_CONTEXT_MINOR_VERSION, 3,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                         EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attributes);
    if (context == EGL_NO_CONTEXT)
        throw Error("headless OpenGL: the EGL device cannot make an OpenGL 3.3 core context");
    m_context = context;
    // No surface (EGL_KHR_surfaceless_context): the frames go to a framebuffer object.
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context))
        throw Error("headless OpenGL: the EGL driver cannot make a context current without a "
                    "surface (EGL_KHR_surfaceless_context)");
    glGenRenderbuffers(1, &m_color);
    glBindRenderbuffer(GL_RENDERBUFFER, m_color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glGenFramebuffers(1, &m_framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, m_framebuffer);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, m_color);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw Error("headless OpenGL: a " + std::to_string(width) + "x" + std::to_string(height) +
                    " RGBA8 framebuffer is incomplete on this driver");
}

HeadlessGl::~HeadlessGl() {
    if (m_context) {
        glDeleteFramebuffers(1, &m_framebuffer);
        glDeleteRenderbuffers(1, &m_color);
        eglMakeCurrent(m_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(m_display, m_context);
    }
    if (m_display) eglTerminate(m_display);
}

std::string HeadlessGl::renderer() const {
    const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    return name ? name : "?";
}

}  // namespace lucent::viewer

// OpenGL 3.3 core for Lucent's own drawing (the viewer, `lucent bench present`). glvnd's
// libOpenGL exports the core entry points for GLX and EGL contexts alike, so prototypes
// suffice; ImGui's OpenGL3 backend loads its own.
#pragma once

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

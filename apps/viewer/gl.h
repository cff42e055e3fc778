// OpenGL 3.3 core for the viewer's own drawing. Linux's libGL (glvnd, Mesa) exports the core
// entry points, so prototypes suffice; ImGui's OpenGL3 backend loads its own.
#pragma once

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

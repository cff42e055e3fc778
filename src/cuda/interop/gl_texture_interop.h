// GlTexture's CUDA side (lucent/display.h): device display frames copied into an OpenGL
// texture through CUDA–OpenGL interop, by a kernel writing through a surface.
#pragma once

#include <memory>

#include "core/gl_texture_interop.h"

namespace lucent::cuda {

/// The interop for OpenGL texture `gl_texture`; throws lucent::Error without a driver.
std::unique_ptr<GlTexture::Impl> make_gl_texture_interop(unsigned gl_texture);

}  // namespace lucent::cuda

// What GlTexture (lucent/display.h) copies device frames with: an interface, implemented by
// the backend that makes frames in device memory (CUDA–OpenGL interop) and made by the
// backend factory, so GlTexture is defined once whatever backends a build has.
#pragma once

#include "lucent/display.h"

namespace lucent {

struct GlTexture::Impl {
    virtual ~Impl() = default;
    /// GlTexture::copy_from: the frame's pixels into the texture, GPU to GPU.
    virtual void copy_from(const DisplayFrame& frame) = 0;
    /// GlTexture::release: unregisters the texture (nothing when not registered).
    virtual void release() = 0;
};

}  // namespace lucent

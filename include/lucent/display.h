// Showing a rendered image: 8-bit sRGB display frames made where the launch left the
// image, and an OpenGL texture they are copied into. On the CUDA backend the
// pixels never leave the GPU (CUDA–OpenGL interop, the path OptiX's GL-interop buffers
// serve); elsewhere they are host memory, uploaded by the application.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "lucent/device/types.h"

namespace lucent {

/// The 8-bit sRGB code of a linear value: the sRGB transfer function (IEC 61966-2-1) of
/// the value clamped to [0, 1], times 255, rounded to nearest; NaN gives 0. The one
/// definition behind PNG files, the viewer and the GPU's display frames.
unsigned char srgb8_from_linear(float linear);

/// Encodes `count` linear RGB pixels (alpha ignored) as RGBA8, alpha 255, equal to
/// srgb8_from_linear channel by channel (a table search, several times faster).
void encode_srgb8_rgba(const float4* linear, size_t count, unsigned char* rgba);

/// The 255 thresholds of srgb8_from_linear: code k is the number of thresholds t[0..254]
/// a value is >= (t[k-1] is the smallest float that encodes to k). The GPU encodes with
/// them, so its codes equal the host's bit for bit.
const float* srgb8_thresholds();

/// A rendered frame ready to show: width x height RGBA8 pixels, row 0 at the top, alpha 255.
/// Made by Context::display_frame on the thread that launches; afterwards independent of
/// the Context (it keeps what it needs alive), so another thread may present it.
class DisplayFrame {
  public:
    virtual ~DisplayFrame() = default;
    unsigned width() const { return m_width; }
    unsigned height() const { return m_height; }
    size_t bytes() const { return size_t(m_width) * m_height * 4; }
    /// True when the pixels are in a GPU's memory (a CUDA launch made them there); then
    /// GlTexture copies them GPU to GPU.
    virtual bool on_device() const = 0;
    /// The pixels in host memory (a download when on_device()).
    virtual std::vector<unsigned char> rgba() const = 0;

    /// A host frame of linear RGB pixels (alpha ignored), encoded with encode_srgb8_rgba.
    static std::shared_ptr<DisplayFrame> from_linear(unsigned width, unsigned height,
                                                     const float4* linear);

  protected:
    DisplayFrame(unsigned width, unsigned height) : m_width(width), m_height(height) {}

  private:
    unsigned m_width, m_height;
};

/// An OpenGL 2D texture that device display frames are copied into with CUDA–OpenGL
/// interop (registered with the GPU of the first frame, again when a frame comes from
/// another GPU), by a kernel writing through a surface: the draw then reads the texture
/// with no further copy (the copy engine's paths were slower: docs/performance.md). Every call
/// needs the OpenGL context that owns the texture current on the calling thread, on the
/// same GPU as the frames. Throws lucent::Error when that cannot be done (no CUDA, an
/// OpenGL driver of another vendor): callers then upload rgba().
class GlTexture {
  public:
    /// `gl_texture`: the name of a GL_TEXTURE_2D texture with internal format GL_RGBA8,
    /// which the caller sizes (glTexImage2D) to the frames before copy_from, and must not
    /// re-specify while registered (release() first).
    explicit GlTexture(unsigned gl_texture);
    ~GlTexture();
    GlTexture(const GlTexture&) = delete;
    GlTexture& operator=(const GlTexture&) = delete;

    /// Copies a device frame's pixels into level 0 of the texture (row 0 of the frame into
    /// texture row 0), GPU to GPU, without waiting: OpenGL commands issued after it see the
    /// pixels. frame.on_device() must be true and the texture GL_RGBA8 of exactly the
    /// frame's size.
    void copy_from(const DisplayFrame& frame);
    /// Unregisters the texture from CUDA (before the caller re-specifies or deletes it).
    void release();

    struct Impl;

  private:
    unsigned m_gl_texture;
    std::unique_ptr<Impl> m;
};

}  // namespace lucent

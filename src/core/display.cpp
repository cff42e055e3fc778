// 8-bit sRGB encoding, host display frames and GlTexture (include/lucent/display.h).
#include "lucent/display.h"

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "backends/backend_factory.h"
#include "core/gl_texture_interop.h"

namespace lucent {

unsigned char srgb8_from_linear(float v) {
    if (!(v > 0.f)) return 0;  // also NaN
    if (v >= 1.f) return 255;
    const float encoded = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
    return (unsigned char)std::lround(encoded * 255.f);
}

namespace {

/// t[k-1] = the smallest positive float that srgb8_from_linear encodes to k or more, found
/// by bisection over the floats' ordered bit patterns (the encoding never decreases).
std::array<float, 255> make_thresholds() {
    std::array<float, 255> t{};
    const uint32_t one = std::bit_cast<uint32_t>(1.0f);
    for (int k = 1; k <= 255; ++k) {
        uint32_t lo = 0, hi = one;  // encode(lo) < k <= encode(hi)
        while (hi - lo > 1) {
            const uint32_t mid = lo + (hi - lo) / 2;
            if (srgb8_from_linear(std::bit_cast<float>(mid)) >= k)
                hi = mid;
            else
                lo = mid;
        }
        t[size_t(k - 1)] = std::bit_cast<float>(hi);
    }
    return t;
}

/// For the host: the code at the start of each bucket of floats sharing their top 16 bits
/// (sign, exponent, 7 mantissa bits) below 1.0; a bucket holds at most a few thresholds, so
/// a value's code is its bucket's plus the thresholds it passes within the bucket.
struct BucketTable {
    static constexpr uint32_t kBuckets = 0x3f80;  // std::bit_cast<uint32_t>(1.0f) >> 16
    std::array<unsigned char, kBuckets> start{};
    BucketTable() {
        for (uint32_t b = 0; b < kBuckets; ++b)
            start[b] = srgb8_from_linear(std::bit_cast<float>(b << 16));
    }
};

/// A display frame in host memory: what the CPU backend (and a GPU whose host copy of the
/// output is the newer) gives Context::display_frame.
class HostDisplayFrame final : public DisplayFrame {
  public:
    HostDisplayFrame(unsigned width, unsigned height)
        : DisplayFrame(width, height), m_rgba(bytes()) {}
    bool on_device() const override { return false; }
    std::vector<unsigned char> rgba() const override { return m_rgba; }
    unsigned char* pixels() { return m_rgba.data(); }

  private:
    std::vector<unsigned char> m_rgba;
};

const std::array<float, 255>& thresholds() {
    static const std::array<float, 255> t = make_thresholds();
    return t;
}

inline unsigned char encode_fast(const BucketTable& table, const float* t, float v) {
    if (!(v > 0.f)) return 0;  // also NaN
    if (v >= 1.f) return 255;
    unsigned k = table.start[std::bit_cast<uint32_t>(v) >> 16];
    while (k < 255 && v >= t[k]) ++k;
    return (unsigned char)k;
}

}  // namespace

const float* srgb8_thresholds() {
    return thresholds().data();
}

void encode_srgb8_rgba(const float4* linear, size_t count, unsigned char* rgba) {
    static const BucketTable table;
    const float* t = thresholds().data();
    for (size_t i = 0; i < count; ++i) {
        rgba[4 * i + 0] = encode_fast(table, t, linear[i].x);
        rgba[4 * i + 1] = encode_fast(table, t, linear[i].y);
        rgba[4 * i + 2] = encode_fast(table, t, linear[i].z);
        rgba[4 * i + 3] = 255;
    }
}

std::shared_ptr<DisplayFrame> DisplayFrame::from_linear(unsigned width, unsigned height,
                                                        const float4* linear) {
    auto frame = std::make_shared<HostDisplayFrame>(width, height);
    encode_srgb8_rgba(linear, size_t(width) * height, frame->pixels());
    return frame;
}

GlTexture::GlTexture(unsigned gl_texture)
    : m_gl_texture(gl_texture), m(core::make_gl_texture_interop(gl_texture)) {}

GlTexture::~GlTexture() {
    m->release();
}

void GlTexture::copy_from(const DisplayFrame& frame) {
    m->copy_from(frame);
}

void GlTexture::release() {
    m->release();
}

}  // namespace lucent

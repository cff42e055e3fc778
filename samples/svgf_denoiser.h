// The temporal denoiser (SVGF, samples/common/svgf_programs.h) on a sample's Context: five
// entry points (temporal, variance, the wavelet pass in both ping-pong directions, keep), the
// history in buffers of its own, and the previous frame's camera for the reprojection.
#pragma once

#include <memory>

#include "lucent/context.h"
#include "samples/atrous_denoiser.h"
#include "samples/common/camera.h"

namespace lucent::samples {

/// SVGF's parameters; the defaults are Schied et al. 2017's (§5: 5 wavelet passes, alpha 0.2,
/// sigma_z 1, sigma_n 128, sigma_l 4).
struct SvgfOptions {
    unsigned iterations = 5;
    float alpha_colour = 0.2f, alpha_moments = 0.2f;
    float sigma_z = 1.0f, sigma_n = 128.0f, sigma_l = 4.0f;
    float normal_cos = 0.9f;       // reprojection: normals within about 25 degrees
    float plane_tolerance = 4.0f;  // ... points within 4 pixel footprints of the plane
    bool temporal = true;          // false: every frame restarts its history (for tests)
};

class SvgfDenoiser {
  public:
    /// Entry points first_entry .. first_entry + 4 (free ones), filtering the float4
    /// `colour` (one new frame, e.g. 1 sample per pixel) guided by `guides` (the G-buffer of
    /// the same frame).
    SvgfDenoiser(Context& ctx, unsigned first_entry, AtrousDenoiser::Guides guides,
                 std::shared_ptr<Buffer> colour, unsigned width, unsigned height);

    /// After the frame's render and G-buffer pass, from `camera`: integrates the frame into
    /// the history, filters it and keeps the history for the next frame. Returns the buffer
    /// holding the result; `launch_ms` gets the launch times added.
    const Buffer& run(const sample_common::PinholeCamera& camera, const SvgfOptions& options,
                      double& launch_ms);
    /// The next frame starts a new history.
    void reset() { m_has_history = false; }

    /// After run(): the integrated illumination, w the history length in frames (1: this
    /// frame restarted it), and its moments (m1, m2, sum of squared weights).
    const Buffer& integrated_colour() const { return *m_integrated_colour; }
    const Buffer& integrated_moments() const { return *m_integrated_moments; }

  private:
    Context& m_ctx;
    unsigned m_first_entry, m_width, m_height;
    std::shared_ptr<Buffer> m_frame, m_pass;
    std::shared_ptr<Buffer> m_integrated_colour, m_integrated_moments, m_ping, m_pong;
    bool m_has_history = false;
    sample_common::PinholeCamera m_previous{};
};

}  // namespace lucent::samples

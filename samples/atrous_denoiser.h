// The edge-avoiding à-trous denoiser (samples/common/atrous_programs.h) on a sample's
// Context: three entry points, one preparing the filter's input, its guide and the mean
// illumination's block sums, two of the same pass program ping-ponging between two images,
// each pass's parameters uploaded into a 1-element buffer before its launch.
#pragma once

#include <memory>

#include "lucent/context.h"
#include "samples/aov.h"

namespace lucent::samples {

class AtrousDenoiser {
  public:
    /// The G-buffer's images, as samples/gbuffer.h makes them (float4, width x height):
    /// albedo (a coverage), normal (w instance), position (w depth).
    struct Guides {
        std::shared_ptr<Buffer> albedo, normal, position;
    };
    /// Entry points first_entry .. first_entry + 2 (free ones), filtering the float4
    /// `colour` (the sample's output) guided by `guides`.
    AtrousDenoiser(Context& ctx, unsigned first_entry, Guides guides,
                   std::shared_ptr<Buffer> colour, unsigned width, unsigned height);

    /// Runs options.iterations passes (after the G-buffer pass and the render). `footprint`
    /// is a pixel's width at depth 1 (2 |V| / height of the pinhole camera). Returns the
    /// buffer holding the result; `launch_ms` gets the passes' launch times added.
    const Buffer& run(const DenoiseOptions& options, float footprint, double& launch_ms);

  private:
    Context& m_ctx;
    Guides m_guides;
    unsigned m_first_entry, m_width, m_height;
    std::shared_ptr<Buffer> m_colour, m_pass, m_ping, m_pong, m_guide, m_sums;
};

/// The mean over the covered pixels of colour / albedo (as the filter demodulates it), its
/// three channels averaged, from the prepare launch's block sums (float2: sum, pixels; every
/// second pixel of every second row); the unit of sigma_colour. 1 when nothing is covered
/// or it is 0.
float mean_illumination(const Buffer& sums);

}  // namespace lucent::samples

// The viewer's denoiser switch on an interactive session's Context: the G-buffer pass, the
// à-trous filter (samples/atrous_denoiser.h) for the progressive image of a resting camera
// and SVGF (samples/svgf_denoiser.h) for one new sample per pixel per frame, made when the
// switch is first turned on.
#pragma once

#include <memory>
#include <vector>

#include "lucent/context.h"
#include "samples/atrous_denoiser.h"
#include "samples/gbuffer.h"
#include "samples/sample.h"
#include "samples/svgf_denoiser.h"

namespace lucent::samples {

class ViewDenoisers {
  public:
    /// `ray_type` and entry points first_entry .. first_entry + 8 must be free on ctx;
    /// `camera` is the session's PinholeCamera buffer, `colour` its float4 output; each of
    /// `materials` gets the G-buffer closest hit.
    ViewDenoisers(Context& ctx, const RenderSettings& settings, unsigned ray_type,
                  unsigned first_entry, std::shared_ptr<Buffer> camera,
                  std::shared_ptr<Buffer> colour,
                  const std::vector<std::shared_ptr<Material>>& materials);

    /// After the frame's render from `camera`: the G-buffer pass and `denoiser` (not kOff);
    /// their stages are added to `passes`. Returns the filtered image.
    const Buffer& run(ViewDenoiser denoiser, const sample_common::PinholeCamera& camera,
                      RenderResult& passes);
    /// SVGF's next frame starts a new history (a reset, an option changed).
    void reset_history() { m_svgf.reset(); }

  private:
    GBufferPass m_gbuffer;
    AtrousDenoiser m_atrous;
    SvgfDenoiser m_svgf;
    DenoiseOptions m_atrous_options;
    SvgfOptions m_svgf_options;
    unsigned m_height;
};

}  // namespace lucent::samples

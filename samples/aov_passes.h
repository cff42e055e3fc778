// What a sample calls for --aov, --denoise and EXR alpha, one mechanism for all: the
// G-buffer pass of primary rays (samples/gbuffer.h) and the à-trous denoiser
// (samples/atrous_denoiser.h) on the sample's own Context, after its render. Nothing is
// created unless RenderSettings::wants_gbuffer().
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "lucent/context.h"
#include "samples/atrous_denoiser.h"
#include "samples/common/camera.h"
#include "samples/gbuffer.h"
#include "samples/sample.h"

namespace lucent::samples {

class AovPasses {
  public:
    /// `ray_type` and `first_entry` .. first_entry + 3 must be free on ctx (the sample's own
    /// ray types and entry points come first); `camera` is its PinholeCamera buffer.
    AovPasses(Context& ctx, const RenderSettings& settings, unsigned ray_type,
              unsigned first_entry, std::shared_ptr<Buffer> camera);

    bool active() const { return m_gbuffer.has_value(); }
    /// Each of the sample's materials needs the G-buffer closest hit (no-op when inactive);
    /// `roots`, when given, are the graphs G-buffer rays trace (GBufferPass::set_roots).
    void add_to(const std::vector<std::shared_ptr<Material>>& materials,
                std::vector<std::shared_ptr<Node>> roots = {});
    /// The sample's float4 output, which the denoiser filters (when settings.denoise).
    void set_colour(std::shared_ptr<Buffer> colour);
    /// After the render: launches the G-buffer pass and the denoiser; fills result.aovs,
    /// adds the stages "G-buffer" and "denoise", and replaces result.image by the filtered
    /// image. `camera` is the one rendered from (for the pixel footprint).
    void finish(const sample_common::PinholeCamera& camera, RenderResult& result);

  private:
    Context& m_ctx;
    const RenderSettings& m_settings;
    unsigned m_first_entry;
    std::optional<GBufferPass> m_gbuffer;
    std::optional<AtrousDenoiser> m_denoiser;
};

}  // namespace lucent::samples

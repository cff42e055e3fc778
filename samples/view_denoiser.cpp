#include "samples/view_denoiser.h"

#include <cmath>
#include <cstdio>

namespace lucent::samples {

const char* view_denoiser_name(ViewDenoiser denoiser) {
    switch (denoiser) {
        case ViewDenoiser::kAtrous:
            return "a-trous";
        case ViewDenoiser::kSvgf:
            return "svgf";
        default:
            return "off";
    }
}

ViewDenoiser next_view_denoiser(ViewDenoiser denoiser) {
    return denoiser == ViewDenoiser::kOff      ? ViewDenoiser::kAtrous
           : denoiser == ViewDenoiser::kAtrous ? ViewDenoiser::kSvgf
                                               : ViewDenoiser::kOff;
}

namespace {

AtrousDenoiser::Guides guides_of(const GBufferPass& gbuffer) {
    return {gbuffer.albedo(), gbuffer.normal(), gbuffer.position()};
}

}  // namespace

ViewDenoisers::ViewDenoisers(Context& ctx, const RenderSettings& settings, unsigned ray_type,
                             unsigned first_entry, std::shared_ptr<Buffer> camera,
                             std::shared_ptr<Buffer> colour,
                             const std::vector<std::shared_ptr<Material>>& materials)
    : m_gbuffer(ctx, ray_type, first_entry, std::move(camera), settings.width, settings.height),
      m_atrous(ctx, first_entry + 1, guides_of(m_gbuffer), colour, settings.width, settings.height),
      m_svgf(ctx, first_entry + 4, guides_of(m_gbuffer), colour, settings.width, settings.height),
      m_atrous_options(settings.denoise_options),
      m_height(settings.height) {
    for (const auto& material : materials) m_gbuffer.add_to(*material);
}

const Buffer& ViewDenoisers::run(ViewDenoiser denoiser, const sample_common::PinholeCamera& camera,
                                 RenderResult& passes) {
    passes.stages.push_back({"G-buffer", m_gbuffer.launch().launch_ms, ""});
    double ms = 0;
    if (denoiser == ViewDenoiser::kSvgf) {
        const Buffer& out = m_svgf.run(camera, m_svgf_options, ms);
        passes.stages.push_back({"denoise (svgf)", ms, ""});
        return out;
    }
    const float footprint = 2.0f * std::sqrt(dot(camera.V, camera.V)) / float(m_height);
    const Buffer& out = m_atrous.run(m_atrous_options, footprint, ms);
    passes.stages.push_back({"denoise (a-trous)", ms, ""});
    return out;
}

}  // namespace lucent::samples

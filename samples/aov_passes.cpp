#include "samples/aov_passes.h"

#include <cmath>
#include <cstdio>

#include "samples/scene_setup.h"

namespace lucent::samples {

AovPasses::AovPasses(Context& ctx, const RenderSettings& settings, unsigned ray_type,
                     unsigned first_entry, std::shared_ptr<Buffer> camera)
    : m_ctx(ctx), m_settings(settings), m_first_entry(first_entry) {
    if (!settings.wants_gbuffer()) return;
    m_gbuffer.emplace(ctx, ray_type, first_entry, std::move(camera), settings.width,
                      settings.height);
}

void AovPasses::add_to(const std::vector<std::shared_ptr<Material>>& materials,
                       std::vector<std::shared_ptr<Node>> roots) {
    if (!m_gbuffer) return;
    for (const auto& material : materials) m_gbuffer->add_to(*material);
    if (!roots.empty()) m_gbuffer->set_roots(std::move(roots));
}

void AovPasses::set_colour(std::shared_ptr<Buffer> colour) {
    if (!m_gbuffer || !m_settings.denoise) return;
    m_denoiser.emplace(m_ctx, m_first_entry + 1,
                       AtrousDenoiser::Guides{m_gbuffer->albedo(), m_gbuffer->normal(),
                                              m_gbuffer->position()},
                       std::move(colour),
                       m_settings.width, m_settings.height);
}

void AovPasses::finish(const sample_common::PinholeCamera& camera, RenderResult& result) {
    if (!m_gbuffer) return;
    const LaunchReport& report = m_gbuffer->launch();
    result.stages.push_back({"G-buffer", report.launch_ms, "primary rays through pixel centres"});
    if (m_denoiser) {
        double ms = 0;
        const float footprint =
            2.0f * std::sqrt(dot(camera.V, camera.V)) / float(m_settings.height);
        const Buffer& filtered = m_denoiser->run(m_settings.denoise_options, footprint, ms);
        char note[120];
        std::snprintf(note, sizeof note, "%u edge-avoiding à-trous passes",
                      m_settings.denoise_options.iterations);
        result.stages.push_back({"denoise", ms, note});
        result.image = image_from_output(filtered);
    }
    result.aovs = m_gbuffer->channels(m_settings.aovs, m_settings.alpha);
}

}  // namespace lucent::samples

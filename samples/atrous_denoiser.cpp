#include "samples/atrous_denoiser.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "samples/common/atrous_programs.h"

namespace lucent::samples {

AtrousDenoiser::AtrousDenoiser(Context& ctx, unsigned first_entry, Guides guides,
                               std::shared_ptr<Buffer> colour, unsigned width, unsigned height)
    : m_ctx(ctx),
      m_guides(std::move(guides)),
      m_first_entry(first_entry),
      m_width(width),
      m_height(height),
      m_colour(std::move(colour)) {
    m_pass = ctx.create_buffer<sample_atrous::AtrousPass>(BufferType::kInput, 1);
    m_ping = ctx.create_buffer<float4>(BufferType::kInputOutput, width, height);
    m_pong = ctx.create_buffer<float4>(BufferType::kInputOutput, width, height);
    m_guide = ctx.create_buffer<float4>(BufferType::kInputOutput, width, height);
    const unsigned block = sample_atrous::kMeanBlock;
    m_sums = ctx.create_buffer<float2>(BufferType::kOutput,
                                       ((width + block - 1) / block) * ((height + block - 1) / block));
    ctx.set_entry_point_count(std::max(ctx.entry_point_count(), first_entry + 3));
    // Entry first: prepare colour -> ping and the guide; first + 1: ping -> pong; first + 2:
    // pong -> ping. Fixed bindings per entry, so no pass changes a variable (which would
    // recompile the scene).
    auto prepare = ctx.create_program(LUCENT_PROGRAM(sample_atrous::atrous_prepare));
    (*prepare)["atrous_pass"] = m_pass;
    (*prepare)["atrous_colour"] = m_colour;
    (*prepare)["atrous_output"] = m_ping;
    (*prepare)["atrous_guide"] = m_guide;
    (*prepare)["atrous_sums"] = m_sums;
    (*prepare)["aov_albedo"] = m_guides.albedo;
    (*prepare)["aov_normal"] = m_guides.normal;
    (*prepare)["aov_position"] = m_guides.position;
    ctx.set_ray_generation_program(first_entry, prepare);
    const std::shared_ptr<Buffer> from[] = {m_ping, m_pong};
    const std::shared_ptr<Buffer> to[] = {m_pong, m_ping};
    for (unsigned e = 0; e < 2; ++e) {
        auto program = ctx.create_program(LUCENT_PROGRAM(sample_atrous::atrous));
        (*program)["atrous_pass"] = m_pass;
        (*program)["atrous_input"] = from[e];
        (*program)["atrous_output"] = to[e];
        (*program)["atrous_guide"] = m_guide;
        (*program)["aov_albedo"] = m_guides.albedo;
        (*program)["aov_position"] = m_guides.position;
        ctx.set_ray_generation_program(first_entry + 1 + e, program);
    }
}

const Buffer& AtrousDenoiser::run(const DenoiseOptions& options, float footprint,
                                  double& launch_ms) {
    const unsigned passes = std::max(1u, options.iterations);
    sample_atrous::AtrousPass pass{};
    pass.demodulate = options.demodulate;
    m_pass->upload(std::vector<sample_atrous::AtrousPass>{pass});
    m_ctx.launch(m_first_entry, m_width, m_height);
    launch_ms += m_ctx.last_launch().launch_ms;
    const float mean = mean_illumination(*m_sums);
    const Buffer* result = m_ping.get();
    for (unsigned i = 0; i < passes; ++i) {
        pass.step = 1u << std::min(i, 15u);
        pass.last = i + 1 == passes;
        // Dammertz et al. 2010 §3.2: sigma_rt halves with each pass.
        pass.sigma_colour = options.sigma_colour * mean * mean * std::ldexp(1.0f, -int(i));
        pass.sigma_normal = options.sigma_normal;
        pass.sigma_position = options.sigma_position;
        pass.footprint = footprint;
        m_pass->upload(std::vector<sample_atrous::AtrousPass>{pass});
        const unsigned entry = 1 + i % 2;  // ping -> pong, then pong -> ping
        m_ctx.launch(m_first_entry + entry, m_width, m_height);
        launch_ms += m_ctx.last_launch().launch_ms;
        result = entry == 1 ? m_pong.get() : m_ping.get();
    }
    return *result;
}

float mean_illumination(const Buffer& sums) {
    const size_t count = sums.size().x;
    const float2* s = sums.data<float2>();
    double sum = 0, covered = 0;
    for (size_t i = 0; i < count; ++i) {  // in a fixed order: the same mean on every backend
        sum += s[i].x;
        covered += s[i].y;
    }
    const double mean = covered > 0 ? sum / covered : 0.0;
    return mean > 0 && std::isfinite(mean) ? float(mean) : 1.0f;
}

}  // namespace lucent::samples

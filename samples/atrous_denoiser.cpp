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
    // Entry first: colour -> ping; first + 1: ping -> pong; first + 2: pong -> ping. Fixed
    // bindings per entry, so no pass changes a variable (which would recompile the scene).
    const std::shared_ptr<Buffer> from[] = {m_colour, m_ping, m_pong};
    const std::shared_ptr<Buffer> to[] = {m_ping, m_pong, m_ping};
    ctx.set_entry_point_count(std::max(ctx.entry_point_count(), first_entry + 3));
    for (unsigned e = 0; e < 3; ++e) {
        auto program = ctx.create_program(LUCENT_PROGRAM(sample_atrous::atrous));
        (*program)["atrous_pass"] = m_pass;
        (*program)["atrous_input"] = from[e];
        (*program)["atrous_output"] = to[e];
        (*program)["aov_albedo"] = m_guides.albedo;
        (*program)["aov_normal"] = m_guides.normal;
        (*program)["aov_position"] = m_guides.position;
        ctx.set_ray_generation_program(first_entry + e, program);
    }
}

const Buffer& AtrousDenoiser::run(const DenoiseOptions& options, float footprint,
                                  double& launch_ms) {
    const unsigned passes = std::max(1u, options.iterations);
    const float mean =
        mean_illumination(*m_colour, *m_guides.albedo, options.demodulate);
    const Buffer* result = m_ping.get();
    for (unsigned i = 0; i < passes; ++i) {
        sample_atrous::AtrousPass pass{};
        pass.step = 1u << std::min(i, 15u);
        pass.first = i == 0;
        pass.last = i + 1 == passes;
        pass.demodulate = options.demodulate;
        // Dammertz et al. 2010 §3.2: sigma_rt halves with each pass.
        pass.sigma_colour = options.sigma_colour * mean * mean * std::ldexp(1.0f, -int(i));
        pass.sigma_normal = options.sigma_normal;
        pass.sigma_position = options.sigma_position;
        pass.footprint = footprint;
        m_pass->upload(std::vector<sample_atrous::AtrousPass>{pass});
        const unsigned entry = i == 0 ? 0 : (i % 2 == 1 ? 1 : 2);
        m_ctx.launch(m_first_entry + entry, m_width, m_height);
        launch_ms += m_ctx.last_launch().launch_ms;
        result = entry == 1 ? m_pong.get() : m_ping.get();
    }
    return *result;
}

float mean_illumination(const Buffer& colour, const Buffer& albedo, bool demodulate) {
    const size_t pixels = size_t(colour.size().x) * std::max(1u, colour.size().y);
    const float4* c = colour.data<float4>();
    const float4* a = albedo.data<float4>();
    double sum = 0;
    size_t covered = 0;
    for (size_t i = 0; i < pixels; ++i) {
        if (a[i].w <= 0.5f) continue;
        float3 v = make_float3(c[i].x, c[i].y, c[i].z);
        if (demodulate) v = v / sample_atrous::demodulation(a[i]);
        const float s = (v.x + v.y + v.z) / 3.0f;
        if (std::isfinite(s)) sum += s;
        ++covered;
    }
    const double mean = covered ? sum / double(covered) : 0.0;
    return mean > 0 ? float(mean) : 1.0f;
}

}  // namespace lucent::samples

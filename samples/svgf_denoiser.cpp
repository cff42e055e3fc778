#include "samples/svgf_denoiser.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "samples/common/svgf_programs.h"

namespace lucent::samples {
namespace {

enum Entry : unsigned { kTemporal, kVariance, kPingToPong, kPongToPing, kKeep, kEntries };

bool same_camera(const sample_common::PinholeCamera& a, const sample_common::PinholeCamera& b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

}  // namespace

SvgfDenoiser::SvgfDenoiser(Context& ctx, unsigned first_entry, AtrousDenoiser::Guides guides,
                           std::shared_ptr<Buffer> colour, unsigned width, unsigned height)
    : m_ctx(ctx), m_first_entry(first_entry), m_width(width), m_height(height) {
    auto image = [&] { return ctx.create_buffer<float4>(BufferType::kInputOutput, width, height); };
    m_frame = ctx.create_buffer<sample_svgf::SvgfFrame>(BufferType::kInput, 1);
    m_pass = ctx.create_buffer<sample_svgf::SvgfPass>(BufferType::kInput, 1);
    m_integrated_colour = image();
    m_integrated_moments = image();
    m_ping = image();
    m_pong = image();
    const auto history_normal = image(), history_position = image();
    const auto history_colour = image(), history_moments = image();
    ctx.set_entry_point_count(std::max(ctx.entry_point_count(), first_entry + kEntries));

    // Fixed bindings per entry, so no launch changes a variable (which would recompile).
    auto program = [&](const ProgramDesc& source, unsigned entry) {
        auto p = ctx.create_program(source);
        ctx.set_ray_generation_program(first_entry + entry, p);
        return p;
    };
    auto temporal = program(LUCENT_PROGRAM(sample_svgf::svgf_temporal), kTemporal);
    (*temporal)["svgf_frame"] = m_frame;
    (*temporal)["svgf_colour"] = std::move(colour);
    (*temporal)["aov_albedo"] = guides.albedo;
    (*temporal)["aov_normal"] = guides.normal;
    (*temporal)["aov_position"] = guides.position;
    (*temporal)["history_normal"] = history_normal;
    (*temporal)["history_position"] = history_position;
    (*temporal)["history_colour"] = history_colour;
    (*temporal)["history_moments"] = history_moments;
    (*temporal)["integrated_colour"] = m_integrated_colour;
    (*temporal)["integrated_moments"] = m_integrated_moments;

    auto variance = program(LUCENT_PROGRAM(sample_svgf::svgf_variance), kVariance);
    (*variance)["svgf_frame"] = m_frame;
    (*variance)["aov_albedo"] = guides.albedo;
    (*variance)["aov_normal"] = guides.normal;
    (*variance)["aov_position"] = guides.position;
    (*variance)["integrated_colour"] = m_integrated_colour;
    (*variance)["integrated_moments"] = m_integrated_moments;
    (*variance)["svgf_output"] = m_ping;

    const std::shared_ptr<Buffer> from[] = {m_ping, m_pong}, to[] = {m_pong, m_ping};
    for (unsigned d = 0; d < 2; ++d) {
        auto atrous = program(LUCENT_PROGRAM(sample_svgf::svgf_atrous), kPingToPong + d);
        (*atrous)["svgf_pass"] = m_pass;
        (*atrous)["aov_albedo"] = guides.albedo;
        (*atrous)["aov_normal"] = guides.normal;
        (*atrous)["aov_position"] = guides.position;
        (*atrous)["svgf_input"] = from[d];
        (*atrous)["svgf_output"] = to[d];
    }

    auto keep = program(LUCENT_PROGRAM(sample_svgf::svgf_keep), kKeep);
    (*keep)["aov_normal"] = guides.normal;
    (*keep)["aov_position"] = guides.position;
    (*keep)["integrated_colour"] = m_integrated_colour;
    (*keep)["integrated_moments"] = m_integrated_moments;
    (*keep)["history_normal"] = history_normal;
    (*keep)["history_position"] = history_position;
    (*keep)["history_colour"] = history_colour;
    (*keep)["history_moments"] = history_moments;
}

const Buffer& SvgfDenoiser::run(const sample_common::PinholeCamera& camera,
                                const SvgfOptions& options, double& launch_ms) {
    const float footprint = 2.0f * std::sqrt(dot(camera.V, camera.V)) / float(m_height);
    sample_svgf::SvgfFrame frame{};
    frame.previous = m_previous;
    frame.footprint = footprint;
    frame.alpha_colour = options.alpha_colour;
    frame.alpha_moments = options.alpha_moments;
    frame.normal_cos = options.normal_cos;
    frame.plane_tolerance = options.plane_tolerance;
    frame.has_history = m_has_history && options.temporal;
    frame.resting = same_camera(camera, m_previous);
    m_frame->upload(std::vector<sample_svgf::SvgfFrame>{frame});
    auto launch = [&](unsigned entry) {
        m_ctx.launch(m_first_entry + entry, m_width, m_height);
        launch_ms += m_ctx.last_launch().launch_ms;
    };
    launch(kTemporal);
    launch(kVariance);  // into ping
    launch(kKeep);
    m_has_history = true;
    m_previous = camera;

    const unsigned passes = std::max(1u, options.iterations);
    const Buffer* result = m_ping.get();
    for (unsigned i = 0; i < passes; ++i) {
        sample_svgf::SvgfPass pass{};
        pass.step = 1u << std::min(i, 15u);
        pass.last = i + 1 == passes;
        pass.sigma_z = options.sigma_z;
        pass.sigma_n = options.sigma_n;
        pass.sigma_l = options.sigma_l;
        pass.footprint = footprint;
        m_pass->upload(std::vector<sample_svgf::SvgfPass>{pass});
        const bool ping_to_pong = i % 2 == 0;
        launch(ping_to_pong ? kPingToPong : kPongToPing);
        result = ping_to_pong ? m_pong.get() : m_ping.get();
    }
    return *result;
}

}  // namespace lucent::samples

#include "samples/gbuffer.h"

#include <algorithm>

#include "samples/common/gbuffer_programs.h"

namespace lucent::samples {

GBufferPass::GBufferPass(Context& ctx, unsigned ray_type, unsigned entry,
                         std::shared_ptr<Buffer> camera, unsigned width, unsigned height)
    : m_ctx(ctx), m_ray_type(ray_type), m_entry(entry), m_width(width), m_height(height) {
    ctx.set_ray_type<sample_gbuffer::GBufferPayload>(ray_type, "gbuffer");
    ctx.set_miss_program(ray_type, ctx.create_program(LUCENT_PROGRAM(sample_gbuffer::gbuffer_miss)));
    m_hit = ctx.create_program(LUCENT_PROGRAM(sample_gbuffer::gbuffer_hit));
    auto image = [&] { return ctx.create_buffer<float4>(BufferType::kInputOutput, width, height); };
    m_albedo = image();
    m_normal = image();
    m_position = image();
    auto program = ctx.create_program(LUCENT_PROGRAM(sample_gbuffer::gbuffer_camera));
    (*program)["camera"] = camera;
    (*program)["gbuffer_ray_type"] = ray_type;
    (*program)["aov_albedo"] = m_albedo;
    (*program)["aov_normal"] = m_normal;
    (*program)["aov_position"] = m_position;
    ctx.set_entry_point_count(std::max(ctx.entry_point_count(), entry + 1));
    ctx.set_ray_generation_program(entry, program);
}

void GBufferPass::add_to(Material& material) const {
    material.set_closest_hit(m_ray_type, m_hit);
}

void GBufferPass::set_roots(std::vector<std::shared_ptr<Node>> roots) {
    m_ctx.set_ray_type<sample_gbuffer::GBufferPayload>(m_ray_type, "gbuffer", true,
                                                       std::move(roots));
}

const LaunchReport& GBufferPass::launch() {
    m_ctx.launch(m_entry, m_width, m_height);
    return m_ctx.last_launch();
}

std::vector<scene::ExrChannel> GBufferPass::channels(const AovSelection& aovs, bool alpha) const {
    const size_t pixels = size_t(m_width) * m_height;
    std::vector<scene::ExrChannel> out;
    // Channel c of each float4 pixel of `buffer`, named `name`.
    auto add = [&](const char* name, const Buffer& buffer, int c) {
        const float4* p = buffer.data<float4>();
        scene::ExrChannel channel{name, std::vector<float>(pixels)};
        for (size_t i = 0; i < pixels; ++i) channel.values[i] = (&p[i].x)[c];
        out.push_back(std::move(channel));
    };
    if (alpha) add("A", *m_albedo, 3);
    if (aovs.albedo) {
        add("Albedo.R", *m_albedo, 0);
        add("Albedo.G", *m_albedo, 1);
        add("Albedo.B", *m_albedo, 2);
    }
    if (aovs.normal) {
        add("Nx", *m_normal, 0);
        add("Ny", *m_normal, 1);
        add("Nz", *m_normal, 2);
    }
    if (aovs.position) {
        add("Px", *m_position, 0);
        add("Py", *m_position, 1);
        add("Pz", *m_position, 2);
    }
    if (aovs.depth) add("Z", *m_position, 3);
    if (aovs.instance) add("InstanceId", *m_normal, 3);
    return out;
}

}  // namespace lucent::samples

#include "samples/camera_session.h"

#include <vector>

#include "samples/scene_setup.h"
#include "samples/stages.h"

namespace lucent::samples {

CameraBuffer::CameraBuffer(Context& ctx)
    : m_buffer(ctx.create_buffer<sample_common::PinholeCamera>(BufferType::kInput, 1)) {
    m_buffer->set_name("camera");
}

void CameraBuffer::set(const sample_common::PinholeCamera& camera) {
    m_buffer->upload(std::vector<sample_common::PinholeCamera>{camera});
}

CameraSession::CameraSession(const Sample& sample, const RenderSettings& settings)
    : m_sample(sample), m_settings(settings), m_ctx(settings.context_options()), m_camera(m_ctx) {}

void CameraSession::start_at(const scene::Camera& camera,
                             const sample_common::PinholeCamera& pinhole) {
    m_initial = camera;
    m_camera.set(pinhole);
}

void CameraSession::set_camera(const scene::Camera& camera) {
    m_camera.set(pinhole_camera(camera, m_settings.aspect()));
    reset();
}

bool CameraSession::set_option(const std::string& name, const std::string& value) {
    RenderSettings changed = m_settings;
    changed.sets[name] = value;
    const OptionValues values = m_sample.read_options(changed);  // checks the value
    if (!apply_options(values)) return false;
    m_settings = changed;
    reset();
    return true;
}

FrameResult CameraSession::frame_of(RenderResult passes, const Buffer& output) {
    FrameResult out;
    out.stages = std::move(passes.stages);
    out.report = passes.report;
    take_frame_pixels(m_ctx, output, m_settings.display_frames, out);
    return out;
}

FrameResult CameraSession::frame() {
    FrameResult out;
    m_ctx.launch(0, m_settings.width, m_settings.height);
    out.report = m_ctx.last_launch();
    add_launch_stages(out.report, out.stages);
    take_frame_pixels(m_ctx, *m_output, m_settings.display_frames, out);
    return out;
}

}  // namespace lucent::samples

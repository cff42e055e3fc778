// The default interactive session (Sample::open) of a sample whose frame is several passes
// (IGI, radiosity): each frame is a full render through Sample::render from the sample's own
// camera, so the viewer can still show it and change its options (IGI's and radiosity's keys).
#include "samples/sample.h"

namespace lucent::samples {
namespace {

class StillSession final : public InteractiveSession {
  public:
    StillSession(const Sample& sample, const RenderSettings& settings)
        : m_sample(sample), m_settings(settings) {
        sample.read_options(settings);  // checks them
        m_settings.repeat = 1;
        m_settings.progress = nullptr;
    }

    std::string backend() const override { return m_backend; }
    std::string backend_notice() const override { return m_notice; }
    scene::Camera initial_camera() const override { return {}; }
    bool fixed_camera() const override { return true; }
    void set_camera(const scene::Camera&) override {}

    bool set_option(const std::string& name, const std::string& value) override {
        RenderSettings changed = m_settings;
        changed.sets[name] = value;
        m_sample.read_options(changed);  // a bad value throws SettingsError
        m_settings = changed;
        return true;
    }

    FrameResult frame() override {
        RenderResult r = m_sample.render(m_settings);
        m_backend = r.backend;
        m_notice = r.backend_notice;
        FrameResult out;
        out.stages = std::move(r.stages);
        if (m_settings.display_frames) {
            std::vector<float4> linear(r.image.pixels.size());
            for (size_t i = 0; i < linear.size(); ++i) linear[i] = make_float4(r.image.pixels[i], 1.f);
            out.display = DisplayFrame::from_linear(r.image.width, r.image.height, linear.data());
        } else {
            out.image = std::move(r.image);
        }
        out.report = r.report;
        return out;
    }

  private:
    const Sample& m_sample;
    RenderSettings m_settings;
    std::string m_backend = "(not yet rendered)", m_notice;
};

}  // namespace

std::unique_ptr<InteractiveSession> Sample::open(const RenderSettings& settings) const {
    return std::make_unique<StillSession>(*this, settings);
}

}  // namespace lucent::samples

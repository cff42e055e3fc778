// `lucent view` for the fog sample: FogScene keeps its camera in a buffer, so a moving camera
// only re-uploads it. Every option is a material variable or changes the scene's shape (the
// fog box, the recursion depth), so options rebuild the scene: cheap for these few triangles.
#include "samples/fog/fog_session.h"

#include "samples/fog/fog.h"
#include "samples/fog/fog_scene.h"
#include "samples/scene_setup.h"
#include "samples/settings_error.h"

namespace lucent::samples {
namespace {

class FogSession final : public InteractiveSession {
  public:
    FogSession(const RenderSettings& settings, const FogOptions& options)
        : m_display_frames(settings.display_frames),
          m_scene(options, settings.width, settings.height, settings.context_options()),
          m_initial(m_scene.orbit_camera(options.orbit_degrees)),
          m_camera(m_initial) {}

    std::string backend() const override { return m_scene.context().backend_name(); }
    std::string backend_notice() const override { return m_scene.context().backend_notice(); }
    scene::Camera initial_camera() const override { return m_initial; }
    void set_camera(const scene::Camera& camera) override { m_camera = camera; }
    bool set_option(const std::string&, const std::string&) override { return false; }

    FrameResult frame() override {
        FrameResult out;
        out.report = m_scene.render(m_camera);
        add_launch_stages(out.report, out.stages);
        take_frame_pixels(m_scene.context(), m_scene.output(), m_display_frames, out);
        return out;
    }

  private:
    bool m_display_frames;
    mutable FogScene m_scene;  // context() is not const
    scene::Camera m_initial, m_camera;
};

}  // namespace

std::unique_ptr<InteractiveSession> open_fog_session(const RenderSettings& settings) {
    const SampleInfo& info = fog_sample_info();
    check_options(settings, info);
    if (!settings.scene.empty())
        throw SettingsError("--scene " + settings.scene +
                            ": the fog sample renders its own scene; leave --scene out");
    return std::make_unique<FogSession>(settings, read_fog_options(settings, info));
}

}  // namespace lucent::samples

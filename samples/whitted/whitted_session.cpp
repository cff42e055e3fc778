// `lucent view` for the Whitted sample: the scene built once, the camera frame in a buffer,
// and the options that are plain variables changed in place (a recompile, no rebuild).
#include <vector>

#include "lucent.h"
#include "samples/scene_setup.h"
#include "samples/whitted/whitted.h"
#include "samples/whitted/whitted_programs.h"
#include "samples/whitted/whitted_scene.h"

namespace lucent::samples {
namespace {

class WhittedSession final : public InteractiveSession {
  public:
    explicit WhittedSession(const RenderSettings& settings)
        : m_settings(settings),
          m_options(read_whitted_options(settings)),
          m_ctx(settings.context_options()) {
        m_output = build_whitted_scene(m_ctx, m_options, settings.width, settings.height);
        m_frame = m_ctx.create_buffer<whitted::ViewFrame>(BufferType::kInput, 1);
        m_frame->set_name("view camera");
        m_camera = m_ctx.create_program(LUCENT_PROGRAM(whitted::whitted_view_camera));
        (*m_camera)["camera"] = m_frame;
        (*m_camera)["antialiasing"] = m_options.antialiasing;
        (*m_camera)["aa_threshold"] = m_options.aa_threshold;
        m_ctx.set_ray_generation_program(0, m_camera);
        set_camera(initial_camera());
    }

    std::string backend() const override { return m_ctx.backend_name(); }
    std::string backend_notice() const override { return m_ctx.backend_notice(); }

    scene::Camera initial_camera() const override {
        const WhittedLayout& layout = whitted_layout();
        scene::Camera camera;
        camera.eye = layout.eye;
        camera.look = layout.lookat;
        camera.up = layout.up;
        camera.fov_degrees = layout.vfov_degrees;
        return camera;
    }

    void set_camera(const scene::Camera& camera) override {
        const PinholeFrame f =
            pinhole_frame(camera, float(m_settings.width) / float(m_settings.height));
        m_frame->upload(std::vector<whitted::ViewFrame>{{camera.eye, f.U, f.V, f.W}});
    }

    bool set_option(const std::string& name, const std::string& value) override {
        RenderSettings changed = m_settings;
        changed.sets[name] = value;
        const WhittedOptions o = read_whitted_options(changed);  // checks the value
        if (o.lights != m_options.lights) return false;  // a buffer of another size: rebuild
        (*m_camera)["antialiasing"] = o.antialiasing;
        (*m_camera)["aa_threshold"] = o.aa_threshold;
        m_ctx.set_max_recursion_depth(unsigned(o.max_depth) + 2);
        m_ctx["max_depth"] = o.max_depth;
        m_ctx["shadows"] = o.shadows;
        m_settings = changed;
        m_options = o;
        return true;
    }

    FrameResult frame() override {
        FrameResult out;
        m_ctx.launch(0, m_settings.width, m_settings.height);
        out.report = m_ctx.last_launch();
        add_launch_stages(out.report, out.stages);
        take_frame_pixels(m_ctx, *m_output, m_settings.display_frames, out);
        return out;
    }

  private:
    RenderSettings m_settings;
    WhittedOptions m_options;
    Context m_ctx;
    std::shared_ptr<Buffer> m_output, m_frame;
    std::shared_ptr<Program> m_camera;
};

}  // namespace

std::unique_ptr<InteractiveSession> open_whitted_session(const RenderSettings& settings) {
    return std::make_unique<WhittedSession>(settings);
}

}  // namespace lucent::samples

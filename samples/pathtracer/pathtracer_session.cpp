// `lucent view` for the path tracer: progressive. Each frame adds one sample per pixel to the
// accumulation buffer, whose w counts them; moving the camera or an option clears it.
#include <vector>

#include "lucent.h"
#include "samples/pathtracer/pathtracer.h"
#include "samples/pathtracer/pathtracer_programs.h"
#include "samples/pathtracer/pathtracer_scene.h"
#include "samples/scene_setup.h"

namespace lucent::samples {
namespace {

class PathSession final : public InteractiveSession {
  public:
    explicit PathSession(const RenderSettings& settings)
        : m_settings(settings),
          m_options(read_path_options(settings)),
          m_ctx(settings.context_options()) {
        m_scene = build_path_scene(m_ctx, settings, m_options);
        m_frame = m_ctx.create_buffer<pathtracer::ViewFrame>(BufferType::kInput, 1);
        m_frame->set_name("view camera");
        m_camera = m_ctx.create_program(LUCENT_PROGRAM(pathtracer::pt_view_camera));
        (*m_camera)["camera"] = m_frame;
        (*m_camera)["accum"] = m_scene.accum;
        (*m_camera)["output"] = m_scene.output;
        set_path_camera_options(*m_camera, m_options);
        m_ctx.set_ray_generation_program(0, m_camera);
        set_camera(initial_camera());
    }

    std::string backend() const override { return m_ctx.backend_name(); }
    std::string backend_notice() const override { return m_ctx.backend_notice(); }
    scene::Camera initial_camera() const override { return m_scene.camera; }
    bool progressive() const override { return true; }

    void set_camera(const scene::Camera& camera) override {
        const PinholeFrame f =
            pinhole_frame(camera, float(m_settings.width) / float(m_settings.height));
        m_frame->upload(std::vector<pathtracer::ViewFrame>{{camera.eye, f.U, f.V, f.W}});
        reset();
    }

    bool set_option(const std::string& name, const std::string& value) override {
        RenderSettings changed = m_settings;
        changed.sets[name] = value;
        const PathOptions o = read_path_options(changed);  // checks the value
        set_path_camera_options(*m_camera, o);
        (*m_scene.miss)["environment"] = make_float3(o.environment);
        m_settings = changed;
        m_options = o;
        reset();
        return true;
    }

    void reset() override {
        // The sample count is the accumulation's w: zero restarts the average (and the
        // random streams, so a resting camera converges to the sample's own render).
        const size_t pixels = size_t(m_settings.width) * m_settings.height;
        m_scene.accum->upload(std::vector<float4>(pixels, make_float4(0.0f, 0.0f, 0.0f, 0.0f)));
        m_samples = 0;
    }

    FrameResult frame() override {
        FrameResult out;
        m_ctx.launch(0, m_settings.width, m_settings.height);
        out.report = m_ctx.last_launch();
        add_launch_stages(out.report, out.stages);
        take_frame_pixels(m_ctx, *m_scene.output, m_settings.display_frames, out);
        out.samples = ++m_samples;
        return out;
    }

  private:
    RenderSettings m_settings;
    PathOptions m_options;
    Context m_ctx;
    PathScene m_scene;
    std::shared_ptr<Buffer> m_frame;
    std::shared_ptr<Program> m_camera;
    unsigned m_samples = 0;
};

}  // namespace

std::unique_ptr<InteractiveSession> open_pathtracer_session(const RenderSettings& settings) {
    return std::make_unique<PathSession>(settings);
}

}  // namespace lucent::samples

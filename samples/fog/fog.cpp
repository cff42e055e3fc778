// The fog sample (Sebald, §3.1): its options, one frame of FogScene for `lucent render`,
// and for `lucent view` the same scene, its camera in a buffer (FogScene) so a moving camera
// only re-uploads it. Every option is a material variable or changes the scene's shape (the
// fog box, the recursion depth), so options rebuild the scene: cheap for these few triangles.
#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "samples/fog/fog_scene.h"
#include "samples/scene_setup.h"
#include "samples/settings_error.h"
#include "samples/stages.h"

namespace lucent::samples {

namespace {

/// The options checked, and --scene refused: the sample has its own scene.
FogOptions checked_options(const Sample& sample, const RenderSettings& settings) {
    const OptionValues values = sample.read_options(settings);
    if (!settings.scene.empty())
        throw SettingsError("--scene " + settings.scene +
                            ": the fog sample renders its own scene (the OptiX SDK tutorial's); "
                            "leave --scene out");
    if (settings.scene_camera)
        throw SettingsError("--camera " + std::to_string(*settings.scene_camera) +
                            ": the fog sample's scene has 0 cameras of its own (its camera "
                            "orbits; --eye --look --up --fov replace it)");
    return read_fog_options(values);
}

/// The orbit's camera, with the parts settings.camera gives replaced.
scene::Camera fog_camera(const FogScene& scene, const FogOptions& options,
                         const RenderSettings& settings) {
    const scene::Camera orbit = scene.orbit_camera(options.orbit_degrees);
    return settings.camera.empty() ? orbit : settings.camera.applied_to(orbit);
}

class FogSession final : public InteractiveSession {
  public:
    FogSession(const Sample& sample, const RenderSettings& settings, const FogOptions& options)
        : m_sample(sample),
          m_settings(settings),
          m_scene(options, settings.width, settings.height, settings.context_options()),
          m_initial(fog_camera(m_scene, options, settings)),
          m_camera(m_initial) {}

    std::string backend() const override { return m_scene.context().backend_name(); }
    std::string backend_notice() const override { return m_scene.context().backend_notice(); }
    scene::Camera initial_camera() const override { return m_initial; }
    void set_camera(const scene::Camera& camera) override { m_camera = camera; }
    bool set_option(const std::string& name, const std::string& value) override {
        RenderSettings changed = m_settings;
        changed.sets[name] = value;
        m_sample.read_options(changed);  // a bad value throws SettingsError
        return false;
    }

    FrameResult frame() override {
        FrameResult out;
        out.report = m_scene.render(m_camera);
        add_launch_stages(out.report, out.stages);
        take_frame_pixels(m_scene.context(), m_scene.output(), m_settings.display_frames, out);
        return out;
    }

  private:
    const Sample& m_sample;
    RenderSettings m_settings;
    mutable FogScene m_scene;  // context() is not const
    scene::Camera m_initial, m_camera;
};

class FogSample final : public Sample {
  public:
    FogSample()
        : Sample(
              "fog",
              "Volumetric fog (Sebald, §3.1) in the OptiX SDK tutorial scene: TEA gradient "
              "noise in x, z times a linear falloff in y, marched along each ray; shadows pass "
              "through",
              {
                  SampleOption::toggle("fog", true, "0: the tutorial scene without the fog box"),
                  SampleOption::number("step", 0.05f, 1e-3f, 10.0f,
                                       "march step along rays in the fog, scene units"),
                  SampleOption::number("height", 2.0f, 0.01f, 100.0f,
                                       "height of the fog box over the floor (the box is 7)"),
                  SampleOption::number("density", 1.5f, 0.0f, 100.0f,
                                       "extinction per unit at full noise at the bottom"),
                  SampleOption::number("noise_scale", 3.0f, 0.01f, 1000.0f,
                                       "lattice size of the gradient noise, scene units"),
                  SampleOption::toggle("noise", true,
                                       "0: uniform density instead of TEA gradient noise"),
                  SampleOption::toggle("falloff", true, "0: no linear falloff with height"),
                  SampleOption::integer("rounds", 2, 1, 64, "TEA rounds of the noise (the paper: 2)"),
                  SampleOption::integer("device", 0, 0, 1 << 30,
                                        "device identifier in the TEA key (Sebald Fig. 4)"),
                  SampleOption::integer("seed", 0, 0, 1 << 30, "seed in the TEA key (Sebald Fig. 4)"),
                  SampleOption::integer("max_depth", 5, 1, 16,
                                        "deepest reflection and refraction tree"),
                  SampleOption::text("environment", "",
                                     "equirectangular .hdr or .exr for the miss program; empty: a "
                                     "procedural sky"),
                  SampleOption::number("orbit", 0.0f, -3600.0f, 3600.0f,
                                       "the camera's angle on its orbit around the scene, degrees"),
                  SampleOption::number(
                      "eye_height", 9.0f, -100.0f, 100.0f,
                      "the camera's height (below the fog's height: inside the fog)"),
                  SampleOption::number(
                      "eye_distance", 20.0f, 0.1f, 1000.0f,
                      "the camera's distance from the scene's axis (below 12: over the floor)"),
              }) {}

    RenderResult render(const RenderSettings& settings) const override {
        const FogOptions options = checked_options(*this, settings);
        const Clock::time_point setup_start = Clock::now();
        FogScene scene(options, settings.width, settings.height, settings.context_options());
        const scene::Camera camera = fog_camera(scene, options, settings);
        RenderResult out = result_for(scene.context());
        out.stages.push_back({"scene setup", ms_since(setup_start),
                              options.fog ? "tutorial scene with fog" : "tutorial scene, no fog"});
        // The first launch compiles; --repeat gives the median of the rest.
        out.report = scene.render(camera);
        add_compile_stages(out.report, out.stages);
        std::vector<double> ms{out.report.launch_ms};
        for (unsigned i = 1; i < settings.repeat; ++i) {
            if (i == 1) ms.clear();
            ms.push_back(scene.render(camera).launch_ms);
            if (settings.progress) settings.progress(i, settings.repeat - 1);
        }
        std::sort(ms.begin(), ms.end());
        const double median = ms[ms.size() / 2];
        out.stages.push_back(
            {"launch", median,
             std::to_string(1000.0 / median) + " frames/s (" +
                 (ms.size() > 1 ? "median of " + std::to_string(ms.size()) : "one") + ")"});
        out.image = image_from_output(scene.output());
        return out;
    }

    std::unique_ptr<InteractiveSession> open(const RenderSettings& settings) const override {
        return std::make_unique<FogSession>(*this, settings, checked_options(*this, settings));
    }
};

const RegisterSample<FogSample> kRegistered(/*help_order=*/60);

}  // namespace
}  // namespace lucent::samples

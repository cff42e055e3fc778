// The fog sample's entry: options, one frame of FogScene, its timings.
#include "samples/fog/fog.h"

#include <algorithm>
#include <chrono>

#include "samples/fog/fog_scene.h"
#include "samples/fog/fog_session.h"
#include "samples/scene_setup.h"
#include "samples/settings_error.h"

namespace lucent::samples {

namespace {

RenderResult render_fog(const RenderSettings& settings) {
    const SampleInfo& info = fog_sample_info();
    check_options(settings, info);
    if (!settings.scene.empty())
        throw SettingsError("--scene " + settings.scene +
                            ": the fog sample renders its own scene (the OptiX SDK tutorial's); "
                            "leave --scene out");
    const FogOptions options = read_fog_options(settings, info);
    const auto setup_start = std::chrono::steady_clock::now();
    FogScene scene(options, settings.width, settings.height, settings.context_options());
    RenderResult out;
    out.backend = scene.context().backend_name();
    out.backend_notice = scene.context().backend_notice();
    out.stages.push_back(
        {"scene setup",
         std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - setup_start)
             .count(),
         options.fog ? "tutorial scene with fog" : "tutorial scene, no fog"});
    // The first launch compiles; --repeat gives the median of the rest.
    out.report = scene.render(options.orbit_degrees);
    add_compile_stages(out.report, out.stages);
    std::vector<double> ms{out.report.launch_ms};
    for (unsigned i = 1; i < settings.repeat; ++i) {
        if (i == 1) ms.clear();
        ms.push_back(scene.render(options.orbit_degrees).launch_ms);
        if (settings.progress) settings.progress(i, settings.repeat - 1);
    }
    std::sort(ms.begin(), ms.end());
    const double median = ms[ms.size() / 2];
    out.stages.push_back({"launch", median,
                          std::to_string(1000.0 / median) + " frames/s (" +
                              (ms.size() > 1 ? "median of " + std::to_string(ms.size()) : "one") +
                              ")"});
    out.image = image_from_output(scene.output());
    return out;
}

}  // namespace

const SampleInfo& fog_sample_info() {
    static const SampleInfo info{
        "fog",
        "Volumetric fog (Sebald, seed §3.1) in the OptiX SDK tutorial scene: TEA gradient noise "
        "in x, z times a linear falloff in y, marched along each ray; shadows pass through",
        {
            {"fog", "1", "0: the tutorial scene without the fog box"},
            {"step", "0.05", "march step along rays in the fog, scene units (0.001..10)"},
            {"height", "2", "height of the fog box over the floor (0.01..100; the box is 7)"},
            {"density", "1.5", "extinction per unit at full noise at the bottom (0..100)"},
            {"noise_scale", "3", "lattice size of the gradient noise, scene units (0.01..1000)"},
            {"noise", "1", "0: uniform density instead of TEA gradient noise"},
            {"falloff", "1", "0: no linear falloff with height"},
            {"rounds", "2", "TEA rounds of the noise (1..64; the paper: 2)"},
            {"device", "0", "device identifier in the TEA key (Sebald Fig. 4)"},
            {"seed", "0", "seed in the TEA key (Sebald Fig. 4)"},
            {"max_depth", "5", "deepest reflection and refraction tree (1..16)"},
            {"environment", "", "equirectangular .hdr or .exr for the miss program; "
                                "empty: a procedural sky"},
            {"orbit", "0", "the camera's angle on its orbit around the scene, degrees"},
            {"eye_height", "9", "the camera's height (below the fog's height: inside the fog)"},
            {"eye_distance", "20",
             "the camera's distance from the scene's axis (below 12: over the floor)"},
        },
        render_fog,
        open_fog_session,
    };
    return info;
}

}  // namespace lucent::samples

#include "samples/progressive_frames.h"

#include <algorithm>
#include <cstdio>
#include <vector>

#include "samples/stages.h"

namespace lucent::samples {

void render_progressive(Context& ctx, const RenderSettings& settings, unsigned default_spp,
                        RenderResult& out) {
    const unsigned spp = settings.spp ? settings.spp : default_spp;
    std::vector<double> frame_ms;
    const Clock::time_point render_start = Clock::now();
    for (unsigned f = 0; f < spp; ++f) {
        ctx.launch(0, settings.width, settings.height);
        const LaunchReport& report = ctx.last_launch();
        if (f == 0) {
            out.report = report;
            add_compile_stages(report, out.stages);
        } else if (report.exception_count() > 0 && out.report.exception_count() == 0) {
            out.report = report;
        }
        frame_ms.push_back(report.launch_ms);
        if (settings.progress) settings.progress(f + 1, spp);
    }
    const double render_ms = ms_since(render_start);
    // The first frame also compiled the scene (and JIT-compiled it): time the others.
    std::vector<double> steady(frame_ms.begin() + (spp > 1 ? 1 : 0), frame_ms.end());
    std::sort(steady.begin(), steady.end());
    const double median = steady[steady.size() / 2];
    char note[200];
    std::snprintf(note, sizeof note, "median of %zu frames (min %.3f, max %.3f)", steady.size(),
                  steady.front(), steady.back());
    out.stages.push_back({"launch (frame)", median, note});
    std::snprintf(note, sizeof note, "%u spp; steady state %.1f samples/pixel/s, %.2f Msamples/s",
                  spp, 1000.0 / median,
                  double(settings.width) * settings.height / (median * 1000.0));
    out.stages.push_back({"render", render_ms, note});
}

}  // namespace lucent::samples

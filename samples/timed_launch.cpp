// Launch timing shared by the samples: the first launch (which compiles the scene, and on
// the GPU the megakernel) apart from the steady state, measured as a median of repeats.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "samples/stages.h"

namespace lucent::samples {

void add_compile_stages(const LaunchReport& report, std::vector<StageTiming>& stages) {
    char split[96];
    std::snprintf(split, sizeof split, "scene compile %.3f ms, acceleration %.3f ms",
                  report.compile_ms, report.accel_ms);
    stages.push_back({"compile + accel", report.compile_ms + report.accel_ms, split});
    if (report.jit_ms > 0)
        stages.push_back(
            {"megakernel JIT", report.jit_ms,
             report.jit_cached ? "loaded from the kernel cache" : "cold NVRTC compile"});
}

void timed_launch(Context& ctx, unsigned entry, const RenderSettings& settings,
                  RenderResult& result) {
    ctx.launch(entry, settings.width, settings.height);
    result.report = ctx.last_launch();
    add_compile_stages(result.report, result.stages);
    if (settings.repeat <= 1) {
        result.stages.push_back({"launch", result.report.launch_ms, ""});
        return;
    }
    std::vector<double> ms, kernel;
    for (unsigned i = 1; i < settings.repeat; ++i) {
        ctx.launch(entry, settings.width, settings.height);
        ms.push_back(ctx.last_launch().launch_ms);
        kernel.push_back(ctx.last_launch().kernel_ms);
        if (settings.progress) settings.progress(i, settings.repeat - 1);
    }
    std::sort(ms.begin(), ms.end());
    std::sort(kernel.begin(), kernel.end());
    const double median = ms[ms.size() / 2];
    char note[200];
    int n = std::snprintf(note, sizeof note, "median of %zu (min %.3f, max %.3f): %.1f frames/s",
                          ms.size(), ms.front(), ms.back(), 1000.0 / median);
    if (kernel.back() > 0)
        std::snprintf(note + n, sizeof note - size_t(n), "; kernel alone %.3f ms",
                      kernel[kernel.size() / 2]);
    result.stages.push_back({"launch", median, note});
}

}  // namespace lucent::samples

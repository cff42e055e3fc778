// Launch timing shared by the samples: the first launch (which compiles the scene, and on
// the GPU the megakernel) apart from the steady state, measured as a median of repeats.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
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

double launch_mrays(double rays, double kernel_ms, double launch_ms, std::string& timing) {
    const bool kernel = kernel_ms > 0;
    timing = kernel ? "kernel" : "launch";
    const double ms = kernel ? kernel_ms : launch_ms;
    return ms > 0 ? rays / (ms * 1e3) : 0.0;
}

void SteadyLaunches::add(const LaunchReport& report) {
    if (report.launch_shape_trial) {
        ++trials;
        ms.clear();
        kernel_ms.clear();
        return;
    }
    ms.push_back(report.launch_ms);
    kernel_ms.push_back(report.kernel_ms);
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
    SteadyLaunches steady;
    const unsigned wanted = settings.repeat - 1;
    for (unsigned i = 0; steady.ms.size() < wanted && i < wanted + kMostTrialLaunches; ++i) {
        ctx.launch(entry, settings.width, settings.height);
        steady.add(ctx.last_launch());
        if (settings.progress) settings.progress(unsigned(steady.ms.size()), wanted);
    }
    std::vector<double> ms = steady.ms, kernel = steady.kernel_ms;
    if (ms.empty()) {  // the tuning never settled within the launches allowed: say so
        result.stages.push_back({"launch", result.report.launch_ms,
                                 "the first launch: the launch-shape tuning was still trying "
                                 "shapes after " + std::to_string(wanted + kMostTrialLaunches) +
                                 " more"});
        return;
    }
    std::sort(ms.begin(), ms.end());
    std::sort(kernel.begin(), kernel.end());
    const double median = ms[ms.size() / 2];
    char note[240];
    int n = std::snprintf(note, sizeof note, "median of %zu (min %.3f, max %.3f): %.1f frames/s",
                          ms.size(), ms.front(), ms.back(), 1000.0 / median);
    if (kernel.back() > 0)
        n += std::snprintf(note + n, sizeof note - size_t(n), "; kernel alone %.3f ms",
                           kernel[kernel.size() / 2]);
    if (steady.trials > 0)
        std::snprintf(note + n, sizeof note - size_t(n), "; after %u launch-shape trials",
                      steady.trials);
    result.stages.push_back({"launch", median, note});
}

}  // namespace lucent::samples

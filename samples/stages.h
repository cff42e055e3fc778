// The timings every sample reports: wall-clock milliseconds since a point, the stages of a
// launch that compiled the scene, the timed launches of a render, and the stages and pixels
// of an interactive frame.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "lucent/context.h"
#include "samples/sample.h"

namespace lucent::samples {

using Clock = std::chrono::steady_clock;

/// Milliseconds of wall-clock time since `start`.
inline double ms_since(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// A render's result, to be filled: the backend `ctx` runs on and why auto chose it.
inline RenderResult result_for(const Context& ctx) {
    RenderResult out;
    out.backend = ctx.backend_name();
    out.backend_notice = ctx.backend_notice();
    return out;
}

/// Appends the stages a launch that compiled the scene reports: "compile + accel", and
/// "megakernel JIT" (cold compile or cache load) when the CUDA backend ran it.
void add_compile_stages(const LaunchReport& report, std::vector<StageTiming>& stages);

/// The launches a median is taken over: those after the CUDA backend's launch-shape tuning.
/// A trial launch runs a shape (or kernel variant) being tried, not the one chosen, so it
/// is left out; one that comes after timing began (a variant compiled in the background
/// arrived, with new shapes to try) also drops the launches before it, since the choice
/// may change.
struct SteadyLaunches {
    std::vector<double> ms, kernel_ms;  // whole launch, and the kernel alone (0: no kernel)
    unsigned trials = 0;                // trial launches left out

    void add(const LaunchReport& report);
};

/// The most launches timed_launch makes beyond the repeats asked for: the tuning spends a
/// handful per kernel, a few more when a variant arrives from its background compile.
constexpr unsigned kMostTrialLaunches = 96;

/// Mrays/s of a launch that traced `rays` rays: from the kernel's own time where the backend
/// measured it (the GPU's CUDA events), else from the whole launch's. `timing` is set to
/// "kernel" or "launch", saying which.
double launch_mrays(double rays, double kernel_ms, double launch_ms, std::string& timing);

/// Launches `entry` over width x height, then more times when `settings.repeat` asks, and
/// fills `result`: report of the first launch, stages "compile + accel", "megakernel JIT"
/// (when it ran) and "launch" (the first, or the median with spread of `repeat - 1` launches
/// after the launch-shape tuning: SteadyLaunches).
void timed_launch(Context& ctx, unsigned entry, const RenderSettings& settings,
                  RenderResult& result);

/// A viewer frame's stages from its launch report: "compile + accel" and "megakernel JIT"
/// when that launch recompiled, then "launch".
void add_launch_stages(const LaunchReport& report, std::vector<StageTiming>& stages);

/// The frame's pixels from a session's 2D float4 output: `out.display` made where the
/// launch left them (`display_frame`: RenderSettings::display_frames), else `out.image` on
/// the host. The display frame's encoding shows as the stage "display frame".
void take_frame_pixels(Context& ctx, const Buffer& output, bool display_frame, FrameResult& out);

}  // namespace lucent::samples

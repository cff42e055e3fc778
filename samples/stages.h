// The timings every sample reports: wall-clock milliseconds since a point, the stages of a
// launch that compiled the scene, the timed launches of a render, and the stages and pixels
// of an interactive frame.
#pragma once

#include <chrono>
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

/// Launches `entry` over width x height, then `settings.repeat - 1` more times when asked,
/// and fills `result`: report of the first launch, stages "compile + accel", "megakernel
/// JIT" (when it ran) and "launch" (the first, or the median of the repeats with spread).
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

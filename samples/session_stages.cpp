// The stage timings of one interactive frame, shared by the samples' sessions.
#include "samples/stages.h"
#include "samples/scene_setup.h"

namespace lucent::samples {

void add_launch_stages(const LaunchReport& report, std::vector<StageTiming>& stages) {
    if (report.recompiled) add_compile_stages(report, stages);  // the JIT runs only then
    stages.push_back({"launch", report.launch_ms, ""});
}

void take_frame_pixels(Context& ctx, const Buffer& output, bool display_frame, FrameResult& out) {
    if (!display_frame) {
        out.image = image_from_output(output);
        return;
    }
    const Clock::time_point start = Clock::now();
    out.display = ctx.display_frame(output);
    const double ms = ms_since(start);
    out.stages.push_back({"display frame", ms, out.display->on_device() ? "on the GPU" : "on the host"});
}

}  // namespace lucent::samples

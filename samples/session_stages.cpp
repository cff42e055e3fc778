// The stage timings of one interactive frame, shared by the samples' sessions.
#include "samples/sample.h"

namespace lucent::samples {

void add_launch_stages(const LaunchReport& report, std::vector<StageTiming>& stages) {
    if (report.recompiled)
        stages.push_back({"compile + accel", report.compile_ms + report.accel_ms, ""});
    if (report.jit_ms > 0)
        stages.push_back(
            {"megakernel JIT", report.jit_ms,
             report.jit_cached ? "loaded from the kernel cache" : "cold NVRTC compile"});
    stages.push_back({"launch", report.launch_ms, ""});
}

}  // namespace lucent::samples

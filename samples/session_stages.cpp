// The stage timings of one interactive frame, shared by the samples' sessions.
#include "samples/sample.h"

namespace lucent::samples {

void add_launch_stages(const LaunchReport& report, std::vector<StageTiming>& stages) {
    if (report.recompiled) add_compile_stages(report, stages);  // the JIT runs only then
    stages.push_back({"launch", report.launch_ms, ""});
}

}  // namespace lucent::samples

// `lucent bench fog`: Sebald's Table 1 — frames/s of the tutorial scene without fog and with
// fog marched at steps 0.1, 0.05 and 0.01, averaged over a camera moving on its orbit.
#pragma once

#include <functional>
#include <string>

#include "lucent/context.h"

namespace lucent::bench {

struct FogBenchOptions {
    BackendKind backend = BackendKind::kCpu;
    std::vector<DeviceSpec> devices;  // non-empty: launches spread over these
    unsigned threads = 0;
    unsigned width = 1024, height = 768;
    unsigned frames = 30;  // along one turn of the orbit, after one warm-up frame
    bool json = false;
    std::function<void(unsigned, unsigned)> progress;  // (done, total) frames; may be empty
};

/// Prints the table (or JSON) and returns 0; throws lucent::Error for a bad option.
int run_fog_bench(const FogBenchOptions& options);

/// What run_fog_bench measures, as the JSON document `lucent bench fog --json` prints,
/// returned instead of printed (Lucent::bench; Python's lucent.bench_fog).
std::string bench_fog_json(FogBenchOptions options);

}  // namespace lucent::bench

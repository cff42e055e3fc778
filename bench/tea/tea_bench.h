// `lucent bench tea`: Sebald's Table 2 — megabytes of TEA output generated in 1 MB launches,
// with the fixed key against the generated per-device key, in MB/s, on any backend.
#pragma once

#include <functional>
#include <string>

#include "lucent/context.h"

namespace lucent::bench {

struct TeaBenchOptions {
    BackendKind backend = BackendKind::kCpu;
    unsigned threads = 0;
    unsigned megabytes = 2048;  // total output per key variant
    unsigned rounds = 2;        // the fog sample uses 2
    unsigned device = 0, seed = 0;
    bool json = false;
    /// Called as megabytes complete (done, total, over both variants); may be empty.
    std::function<void(unsigned, unsigned)> progress;
};

/// Runs both variants and prints MB/s (and an XOR checksum of all output) per variant.
/// Throws lucent::Error for a bad option (naming it and its range).
int run_tea_bench(const TeaBenchOptions& options);

/// What run_tea_bench measures, as the JSON document `lucent bench tea --json` prints,
/// returned instead of printed (Lucent::bench; Python's lucent.bench_tea).
std::string bench_tea_json(TeaBenchOptions options);

}  // namespace lucent::bench

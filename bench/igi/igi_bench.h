// `lucent bench igi`: the experiment of Marques and Santos (Fig. 4 and 5) — canonical
// IGI, then imperfect visibility, downsampling and interleaving added one after the other,
// each with 30, 90 and 180 VPLs: frames/s and the share of each stage of the frame.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "lucent/context.h"

namespace lucent::bench {

struct IgiBenchOptions {
    std::string scene = "cornell";  // built-in name or file
    BackendKind backend = BackendKind::kCpu;
    std::vector<DeviceSpec> devices;  // non-empty: launches spread over these
    unsigned threads = 0;
    std::shared_ptr<Ranks> ranks;  // non-null: launches spread over these processes (mpirun)
    unsigned width = 800, height = 600;  // the paper's resolution
    unsigned frames = 10;                // timed after one warm-up frame
    std::vector<unsigned> vpls{30, 90, 180};
    unsigned downsample = 4, interleave = 3;  // the paper's windows
    // The first reflected hits' indirect light as a G-buffer layer of its own (the sample's
    // reflection_layer option); false: inline, as in the paper.
    bool reflection_layer = true;
    bool json = false;
    /// Called as configurations complete (done, total); may be empty.
    std::function<void(unsigned, unsigned)> progress;
};

/// Runs every configuration and prints a table (or one JSON object); returns the exit code.
/// Throws lucent::Error for a bad option (naming it and its range) or scene.
int run_igi_bench(const IgiBenchOptions& options);

/// What run_igi_bench measures, as the JSON document `lucent bench igi --json` prints,
/// returned instead of printed (Lucent::bench; Python's lucent.bench_igi).
std::string bench_igi_json(IgiBenchOptions options);

}  // namespace lucent::bench

// `lucent bench curves`: primary and diffuse rays into a procedural head of hair made of
// built-in curves (issue figures: at least 100K cubic segments at 3840x2160 on the GPU).
#pragma once

#include <string>

#include "lucent/context.h"

namespace lucent::bench {

struct CurvesBenchOptions {
    BackendKind backend = BackendKind::kCpu;
    unsigned threads = 0;
    unsigned segments = 100000;  // curve segments in all
    CurveType type = kCurveCubicBSpline;
    unsigned width = 1024, height = 768;
    int repeat = 5;  // timed launches of each ray set
    bool json = false;
};

/// Prints the table (or JSON) and returns 0; throws lucent::Error for a bad option (naming it).
int run_curves_bench(const CurvesBenchOptions& options);

/// What run_curves_bench measures, as the JSON document `lucent bench curves --json` prints,
/// returned instead of printed (Lucent::bench; Python's lucent.bench_curves).
std::string bench_curves_json(CurvesBenchOptions options);

}  // namespace lucent::bench

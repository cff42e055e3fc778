// `lucent bench spheres`: primary rays into a field of spheres, built-in spheres against the
// same spheres as a custom intersection program, in one run on one backend (issue figures:
// 1M spheres at 3840x2160 on the GPU).
#pragma once

#include <functional>
#include <string>

#include "lucent/context.h"

namespace lucent::bench {

struct SpheresBenchOptions {
    BackendKind backend = BackendKind::kCpu;
    unsigned threads = 0;
    unsigned count = 1000000;  // spheres
    unsigned width = 1024, height = 768;
    int repeat = 5;  // timed launches of each path, alternating
    bool json = false;
};

/// Prints the table (or JSON) and returns 0. Throws lucent::Error for a bad option (naming
/// it), or, after printing, when the two paths disagree on more than one pixel in 10,000.
int run_spheres_bench(const SpheresBenchOptions& options);

/// What run_spheres_bench measures, as the JSON document `lucent bench spheres --json`
/// prints, returned instead of printed (Lucent::bench; Python's lucent.bench_spheres).
std::string bench_spheres_json(SpheresBenchOptions options);

}  // namespace lucent::bench

// `lucent bench spheres`: primary rays into a field of spheres, built-in spheres against the
// same spheres as a custom intersection program, in one run on one backend (issue figures:
// 1M spheres at 3840x2160 on the GPU).
#pragma once

#include <functional>

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

/// Prints the table (or JSON); returns the exit code (1 when the two paths disagree).
int run_spheres_bench(const SpheresBenchOptions& options);

}  // namespace lucent::bench

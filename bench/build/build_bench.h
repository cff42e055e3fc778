// `lucent bench build`: the BVH build time of a scene, on the CPU beside Embree, or the GPU
// builder against the host one (build_bench_cuda.h).
#pragma once

#include <string>

namespace lucent::bench {

struct BuildBenchOptions {
    std::string scene;
    int repeat = 5;
    unsigned threads = 0;
    bool peer = true;
    bool json = false;
    std::string backend = "cpu";  // "cpu", or "cuda": the GPU builder against the host one
    unsigned subdivide = 0;       // each triangle cut into 4 at its edge midpoints, N times
    unsigned width = 3840, height = 2160;  // --backend cuda: the rays both trees trace
};
/// Prints build time (median), Mtris/s, SAH cost and node count, and the peer's build time.
/// Throws lucent::Error for a bad option (naming it and the fix) or a bad scene (file:line).
int run_bench_build(const BuildBenchOptions& options);

/// What run_bench_build measures, as the JSON document `lucent bench build --json` prints
/// (its keys: docs/cli.md, "lucent bench build"), returned instead of printed: `bench build`
/// from a C++ program (Lucent::bench) and from Python (lucent.bench_build).
std::string bench_build_json(BuildBenchOptions options);

}  // namespace lucent::bench

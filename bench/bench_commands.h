// `lucent bench rays` and `lucent bench build` (ray sets of shared/BENCH.md).
#pragma once

#include <string>

#include "lucent/device/vector_math.h"

namespace lucent::bench {

struct RaysOptions {
    std::string scene;  // an OBJ file
    bool has_camera =
        false;  // eye/look/up/fov/light given; else read from cameras.txt beside the scene
    float3 eye{0, 0, 0}, look{0, 0, -1}, up{0, 1, 0};
    float fov = 60;
    float3 light{0, 0, 0};
    unsigned width = 1024, height = 768;
    int repeat = 5;               // timed repeats (median reported), after one warm-up
    unsigned threads = 0;         // 0 = all cores
    bool peer = true;             // run Embree on the same rays when built with it
    bool json = false;            // machine-readable output
    std::string backend = "cpu";  // "cpu", or "cuda" (bench/bench_rays_cuda.h)
};
/// Prints one line per ray kind (primary, shadow, diffuse) with Mrays/s and checksums,
/// and the peer's lines and ratios. Returns the process exit code; throws lucent::Error
/// for bad input (missing file, bad OBJ) with file:line.
int run_bench_rays(const RaysOptions& options);

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
int run_bench_build(const BuildBenchOptions& options);

}  // namespace lucent::bench

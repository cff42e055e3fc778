// `lucent bench rays`: the ray sets of shared/BENCH.md traced on the CPU (and beside it
// Embree) or on the GPU (rays_bench_cuda.h).
#pragma once

#include <string>

#include "lucent/context.h"
#include "lucent/device/vector_math.h"
#include "lucent/nodes.h"

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
    bool programs = false;  // also the ray sets through a program module (programs_bench.h)
    // The BVH the programs' scene is built with, and with --backend cuda the one the kernels
    // trace: kAuto (on the GPU, object splits only, then upgraded to the host's tree with
    // spatial splits unless tree_upgrades is kOff) or kBinnedSah (the host's, with spatial
    // splits). The CPU kernels always trace TriangleAccel's tree (spatial splits).
    Builder builder = Builder::kAuto;
    // The programs' upgrades of the GPU-built tree: before the first launch, so that every
    // timed launch traces the same tree, or off (the GPU-built tree alone).
    TreeUpgrades tree_upgrades = TreeUpgrades::kWithBuild;
    std::string backend = "cpu";  // "cpu", or "cuda" (rays_bench_cuda.h)
};
/// Prints one line per ray kind (primary, shadow, diffuse) with Mrays/s and checksums,
/// and the peer's lines and ratios. Returns the process exit code; throws lucent::Error
/// for bad input (missing file, bad OBJ) with file:line.
int run_bench_rays(const RaysOptions& options);

/// What run_bench_rays measures, as the JSON document that `lucent bench rays --json` prints
/// (its keys: docs/cli.md, "lucent bench rays"), returned instead of printed, whatever
/// options.json says: `lucent bench rays` from a C++ program (Lucent::bench) and from Python
/// (lucent.bench_rays). Nothing is written to stdout. Throws lucent::Error for a bad option
/// (naming it and the fix) or a bad scene file (file:line).
std::string bench_rays_json(RaysOptions options);

}  // namespace lucent::bench

// `lucent bench rays --programs`: the BENCH.md ray sets traced by an ordinary program
// module (rays_programs.h) launched through a Context, as a user's programs are, on the CPU
// or the CUDA backend. Beside the bare kernels' figures it shows what the engine's own
// per-ray path (ray generation, trace, closest hit or miss) costs, with each ray waited
// for (trace(), occluded()) or deferred (trace_deferred(), occluded_deferred()).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "bench/common/rate.h"
#include "bench/common/ray_checksums.h"
#include "bench/rays/ray_sets.h"
#include "lucent/context.h"
#include "scene/obj_mesh.h"

namespace lucent::bench {

/// The three ray sets of BENCH.md.
enum class RayKind { kPrimary, kShadow, kDiffuse };

/// Timed passes of other engines (the bare kernels, a peer) over the rays a set's launch
/// traces, seconds each, in a fixed order of engines.
using PairedPasses = std::function<std::vector<double>(RayKind kind, const RaySet& rays)>;

struct ProgramsInput {
    const scene::ObjMesh* mesh = nullptr;
    const RaySet* primary = nullptr;  // primary_rays(); shadow and diffuse follow from its hits
    float3 light{0, 0, 0};
    BackendKind backend = BackendKind::kCpu;
    unsigned threads = 0;  // CPU workers, 0 = one per core
    int repeat = 5;        // timed launches per ray set (median), after one warm-up launch
    Builder builder = Builder::kAuto;  // the GeometryGroup's acceleration
    TreeUpgrades tree_upgrades = TreeUpgrades::kWithBuild;  // of a GPU-built (kAuto) tree
    // The image the primary rays cover. With tile_order, each set's rays are stored, and so
    // launched, in the order of `bench rays --backend cuda`'s kernels: by 8x4 tiles of their
    // pixels (ray_order.cuh), so that a warp traces a compact patch of the image, as the
    // kernels' warps do and as a 2D launch's warps do; else in pixel order.
    unsigned width = 0, height = 0;
    bool tile_order = false;
    // The module's deferred entry points (closest_rays_deferred, shadow_rays_deferred):
    // trace_deferred() and occluded_deferred() where the others call trace() and occluded().
    bool deferred = false;
    // When set, each timed launch has a neighbour: these passes run beside it, before it
    // and after it in turn (A B, B A, ...), as the kernels and the peer take turns. The
    // machines this runs on slow down for seconds at a time, so a ratio of two rates
    // timed seconds apart measures the machine as much as the engines.
    PairedPasses paired_passes;
};

/// The programs' rate over each paired engine's, per ray set: medians over the timed
/// launches of (the engine's pass seconds / the neighbouring launch's seconds).
struct PairedRatios {
    double primary = 0, shadow = 0, diffuse = 0;
};

/// Mrays/s per ray set and the checksums, in RayChecksums' terms.
struct ProgramsResult : RayChecksums {
    Rate primary, shadow, diffuse;
    std::string backend;  // the Context's backend name
    // What a launch's time is: "launch" (the CPU backend's whole launch, programs and
    // thread pool) or "kernel" (the megakernel alone, CUDA events).
    std::string timing;
    // CUDA: the kernel variant each set's timed launches ran, as the launch-shape tuning
    // chose it ("as compiled", "registers capped", "trace inlined", or both); empty on the CPU.
    std::string primary_variant, shadow_variant, diffuse_variant;
    // CUDA: GPU-built trees replaced by their upgrades (ProgramsInput::tree_upgrades).
    unsigned trees_upgraded = 0;
    // With ProgramsInput::paired_passes: one entry per paired engine, in its order.
    std::vector<PairedRatios> paired;
};

/// Builds the Context (one GeometryTriangles under a GeometryGroup, the module's programs),
/// launches each ray set `repeat` times after a warm-up and reads back the answers of the
/// last launch. Throws lucent::Error (no GPU for BackendKind::kCuda, a failed launch).
ProgramsResult run_programs(const ProgramsInput& input);

}  // namespace lucent::bench

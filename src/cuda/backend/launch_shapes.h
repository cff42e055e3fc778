// How the CUDA backend launches its megakernel: the share of each SM's on-chip memory given
// to shared memory (the rest is L1, where the trace frames in local memory live), and how it
// picks that share per entry point by timing the first launches.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

namespace lucent::cuda {

/// A launch shape: which compiled variant of the kernel, the carveout, and the persistent
/// grid they let run at once.
struct LaunchShape {
    int carveout = 0;  // percent of the largest shared-memory configuration
    int grid = 1;      // blocks: resident blocks per SM x SMs
    int variant = 0;   // 0: the kernel as compiled; 1: its register-capped variant
};

/// What a block needs of the SM's shared memory, in bytes (driver attributes).
struct SharedMemoryNeeds {
    int static_per_block = 0;    // the kernel's own (the runtime's per-thread state)
    int reserved_per_block = 0;  // the driver's, per block
    int per_sm = 0;              // the largest configuration of one SM
};

/// The carveouts to try, one per count of resident blocks per SM: from `by_registers` (the
/// most the registers allow; shape 0, "occupancy first") down to one block (carveout 0), each
/// the smallest that holds its count, so the rest of the SM's memory is L1. Counts that the
/// shared-memory configurations' granularity merges appear once. `resident_blocks(carveout)`
/// asks the driver how many blocks a carveout lets run.
///
/// Measured (docs/performance.md): IGI, the path tracer and the fog run 2 to 2.7 times faster
/// with every block resident; the Whitted sample, whose deep recursion keeps large trace
/// frames in local memory, runs fastest with two blocks per SM (H200: 1,079 frames/s, against
/// 943 with one block and 917 with four). No count is right for every program.
std::vector<int> launch_shape_carveouts(int by_registers, const SharedMemoryNeeds& needs,
                                        const std::function<int(int)>& resident_blocks);

/// Per entry point and launch size: launches 1 and 2 run shape 0 (the first warms up, the
/// second is timed), launches 3 to n + 1 shapes 1 to n - 1; from then on, the fastest of
/// those n, per launch index (a device of several runs a different share of each launch).
/// Trials start at the third launch so that a job launching an entry twice (a denoiser's
/// ping-pong passes in one render) never runs a trial shape. Shapes added later (a variant
/// of the kernel compiled in the background) reopen the choice: one untimed launch, one
/// timed launch of each new shape, then the fastest of all.
class ShapeTuning {
  public:
    explicit ShapeTuning(size_t shapes = 1)
        : m_ms(shapes == 0 ? 1 : shapes, 0.0), m_timed(m_ms.size(), false) {}
    int next_shape() const;
    /// The time of a launch of `shape`, per launch index.
    void record(int shape, double ms_per_index);
    /// `count` more shapes to time, numbered after the present ones.
    void add_shapes(size_t count);
    /// The chosen shape, or -1 while still trying.
    int choice() const { return m_choice; }

  private:
    std::vector<double> m_ms;  // per shape
    std::vector<bool> m_timed;
    unsigned m_warm_ups = 1;  // launches still to run untimed
    int m_choice = -1;
};

}  // namespace lucent::cuda

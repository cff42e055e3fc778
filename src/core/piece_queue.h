// The shared queue a multi-device launch is taken from: rows of the launch grid (64-index
// runs in a one-row launch), handed out in pieces sized by each device's speed.
#pragma once

#include <mutex>
#include <optional>
#include <vector>

#include "core/backend.h"

namespace lucent::core {

class PieceQueue {
  public:
    /// `speeds`: each device's launch indices per millisecond, measured on earlier launches
    /// (all zero: not measured yet). `fixed_units`: every piece this many units; 0 = sized.
    PieceQueue(const LaunchSpec& spec, std::vector<double> speeds, unsigned fixed_units);

    /// The next piece for `device`, or nothing when the launch is all handed out or when
    /// the others would finish the rest before this device finished a piece (a slow device,
    /// the CPU beside GPUs, stops taking work instead of making everyone wait for it).
    std::optional<LaunchPiece> take(unsigned device);

    /// Units in the launch, and the smallest piece in units: a launch with fewer than two
    /// smallest pieces per device is not worth splitting.
    uint64_t units() const { return m_units; }
    uint64_t min_units() const { return m_min_units; }

  private:
    uint64_t m_unit_indices;  // launch indices per unit (a row, or 64)
    uint64_t m_count;         // launch indices in all
    uint64_t m_units;
    uint64_t m_min_units;
    uint64_t m_fixed_units;
    std::vector<double> m_speeds;
    /// A piece is this device's share of what is left over this (LUCENT_PIECE_DIVISOR).
    double m_divisor = 2.0;
    std::mutex m_mutex;
    uint64_t m_next = 0;  // first unit not handed out
};

}  // namespace lucent::core

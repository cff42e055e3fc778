// The kept rows of index-local launches across ranks, re-balanced from the ranks' measured
// busy times (docs/distributed.md, "Re-balancing the kept rows"). A pure function of what
// every rank learns in the launch's all-gather, so every rank computes the same answer.
#pragma once

#include <cstdint>
#include <vector>

#include "core/backend.h"

namespace lucent::core {

struct RowBalance {
    bool moved = false;
    /// Per rank: the pieces it keeps from now on.
    std::vector<std::vector<LaunchPiece>> kept;
    /// Per rank: the ranges it held and hands to another rank (their elements move).
    std::vector<std::vector<LaunchPiece>> given;
    /// The slowest rank's busy time over the balanced one's, as measured (1 = balanced).
    double imbalance = 1.0;
};

/// `kept[r]`: rank r's pieces (launch index ranges; together they cover the launch once);
/// `busy_ms[r]`: its time running them, summed over the same launches for every rank.
/// Each rank's share becomes proportional to its speed (indices per ms), the ranks keeping
/// the order of their rows, so rows move only across the boundaries between neighbours.
/// Nothing moves unless the slowest rank is more than `threshold` above the balanced time.
/// Every cut is `granule` indices from the start of the range it cuts (pieces start at
/// multiples of the granule: whole rows, and whole CPU tiles where the pieces allow), and
/// every rank keeps at least one granule where the launch has that many.
RowBalance balance_rows(const std::vector<std::vector<LaunchPiece>>& kept,
                        const std::vector<double>& busy_ms, uint64_t granule, double threshold);

/// The rows that no rank keeps: each frame they go to whichever rank is free first, which
/// evens out what the kept rows cannot (a rank slower in one frame than the frames before).
struct SharedTail {
    /// Per rank: the pieces it keeps, its others given to the tail.
    std::vector<std::vector<LaunchPiece>> kept;
    /// Per rank: the ranges it gave to the tail (their elements go to every rank).
    std::vector<std::vector<LaunchPiece>> given;
    /// The tail, in pieces of a granule (rank order).
    std::vector<LaunchPiece> shared;
};

/// Each rank gives the tail the last `fraction` of its rows (whole granules, cut as in
/// balance_rows), where it holds at least two granules.
SharedTail share_tail(const std::vector<std::vector<LaunchPiece>>& kept, double fraction,
                      uint64_t granule);

}  // namespace lucent::core

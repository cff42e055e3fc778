#include "core/piece_queue.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numeric>

namespace lucent::core {

namespace {
constexpr uint64_t kOneRowUnit = 64;  // launch indices per unit of a one-row launch
/// The smallest piece: 4 rows (a GPU warp's tile is 8x4) or 64 x 64 indices; below that a
/// piece's fixed cost (a kernel launch, a wait) outweighs its work.
constexpr uint64_t kMinRows = 4, kMinOneRowUnits = 64;
}  // namespace

PieceQueue::PieceQueue(const LaunchSpec& spec, std::vector<double> speeds, unsigned fixed_units)
    : m_unit_indices(spec.by_rows() ? spec.size.x : kOneRowUnit),
      m_count(spec.count()),
      m_units((m_count + m_unit_indices - 1) / m_unit_indices),
      m_min_units(spec.by_rows() ? kMinRows : kMinOneRowUnits),
      m_fixed_units(fixed_units),
      m_speeds(std::move(speeds)) {
    // Read once: a queue is made for every launch.
    static const double divisor = [] {
        const char* d = std::getenv("LUCENT_PIECE_DIVISOR");
        return d ? std::max(1.0, std::atof(d)) : 2.0;
    }();
    m_divisor = divisor;
}

std::optional<LaunchPiece> PieceQueue::take(unsigned device) {
    std::lock_guard lock(m_mutex);
    const uint64_t left = m_units - m_next;
    if (left == 0) return std::nullopt;
    uint64_t units = m_fixed_units;
    if (units == 0) {
        // Guided self-scheduling (Polychronopoulos and Kuck 1987) weighted by speed: half of
        // this device's share of what is left, so pieces shrink towards the end and the
        // devices finish together. Unmeasured devices count as equals.
        const double total = std::accumulate(m_speeds.begin(), m_speeds.end(), 0.0);
        const double mine = m_speeds[device];
        const double share = total > 0 && mine > 0 ? mine / total : 1.0 / m_speeds.size();
        units = std::max<uint64_t>(m_min_units,
                                   uint64_t(std::ceil(share * double(left) / m_divisor)));
        units = std::min(units, left);
        const double fastest = *std::max_element(m_speeds.begin(), m_speeds.end());
        if (total > 0 && mine > 0 && mine < fastest) {
            // Would the others, at their speed, finish everything left before this device
            // finished this piece? Then leave it to them (the fastest device always takes,
            // so everything is handed out).
            const double others = total - mine;
            if (double(units) / mine > double(left) / others) return std::nullopt;
        }
    }
    units = std::min(units, left);
    LaunchPiece piece;
    piece.first = m_next * m_unit_indices;
    m_next += units;
    piece.last = std::min(m_count, m_next * m_unit_indices);
    return piece;
}

}  // namespace lucent::core

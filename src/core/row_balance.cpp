#include "core/row_balance.h"

#include <algorithm>
#include <cmath>

namespace lucent::core {

namespace {

/// One of the ranks' ranges, in the sequence of all ranks' ranges in rank order.
struct Segment {
    LaunchPiece range;
    int owner = 0;
    uint64_t position = 0;  // of its first index in the sequence
};

/// `position` moved to the nearest cut that is a whole number of granules into the range
/// holding it (at most to that range's end, which is the next range's start).
uint64_t snap(uint64_t position, const std::vector<Segment>& sequence, uint64_t granule) {
    for (const Segment& s : sequence) {
        const uint64_t length = s.range.last - s.range.first;
        if (position >= s.position + length) continue;
        const uint64_t offset = position - s.position;
        const uint64_t granules = (offset + granule / 2) / granule;
        return s.position + std::min(length, granules * granule);
    }
    return position;
}

void append(std::vector<LaunchPiece>& pieces, LaunchPiece piece) {
    if (!pieces.empty() && pieces.back().last == piece.first)
        pieces.back().last = piece.last;  // contiguous: one piece
    else
        pieces.push_back(piece);
}

}  // namespace

RowBalance balance_rows(const std::vector<std::vector<LaunchPiece>>& kept,
                        const std::vector<double>& busy_ms, uint64_t granule, double threshold) {
    RowBalance out;
    out.kept = kept;
    out.given.assign(kept.size(), {});
    const size_t ranks = kept.size();
    if (ranks < 2 || busy_ms.size() != ranks || granule == 0) return out;

    std::vector<Segment> sequence;
    std::vector<uint64_t> held(ranks, 0);
    uint64_t total = 0;
    for (size_t r = 0; r < ranks; ++r)
        for (const LaunchPiece& p : kept[r]) {
            sequence.push_back({p, int(r), total});
            held[r] += p.last - p.first;
            total += p.last - p.first;
        }
    // Speeds in indices per ms; a rank that holds nothing has no measured speed, and keeps
    // none (it only happens where the launch has fewer granules than ranks).
    std::vector<double> speed(ranks, 0.0);
    double speeds = 0, slowest = 0;
    for (size_t r = 0; r < ranks; ++r) {
        if (held[r] == 0) continue;
        if (!(busy_ms[r] > 0) || !std::isfinite(busy_ms[r])) return out;  // not measured
        speed[r] = double(held[r]) / busy_ms[r];
        speeds += speed[r];
        slowest = std::max(slowest, busy_ms[r]);
    }
    if (!(speeds > 0)) return out;
    const double balanced_ms = double(total) / speeds;
    out.imbalance = slowest / balanced_ms;
    if (!(out.imbalance > 1.0 + threshold)) return out;

    // The new boundaries between ranks in the sequence: shares by speed, at least a granule
    // each where there are enough, cut where a granule ends.
    const uint64_t least = total >= ranks * granule ? granule : 0;
    std::vector<uint64_t> bound(ranks + 1, 0);
    bound[ranks] = total;
    double share = 0;
    for (size_t r = 0; r + 1 < ranks; ++r) {
        share += double(total) * speed[r] / speeds;
        uint64_t b = uint64_t(std::llround(share));
        const uint64_t high = total - (ranks - 1 - r) * least;
        b = std::clamp<uint64_t>(b, std::min(high, bound[r] + least), high);
        bound[r + 1] = std::max(bound[r], snap(b, sequence, granule));
    }

    std::vector<std::vector<LaunchPiece>> fresh(ranks);
    for (const Segment& s : sequence) {
        const uint64_t end = s.position + (s.range.last - s.range.first);
        for (size_t q = 0; q < ranks; ++q) {
            const uint64_t from = std::max(s.position, bound[q]), to = std::min(end, bound[q + 1]);
            if (from >= to) continue;
            const LaunchPiece part{s.range.first + (from - s.position),
                                   s.range.first + (to - s.position)};
            append(fresh[q], part);
            if (int(q) != s.owner) {
                append(out.given[size_t(s.owner)], part);
                out.moved = true;
            }
        }
    }
    if (out.moved) out.kept = std::move(fresh);
    return out;
}

SharedTail share_tail(const std::vector<std::vector<LaunchPiece>>& kept, double fraction,
                      uint64_t granule) {
    SharedTail out;
    out.kept = kept;
    out.given.assign(kept.size(), {});
    if (granule == 0 || !(fraction > 0)) return out;
    for (size_t r = 0; r < kept.size(); ++r) {
        std::vector<LaunchPiece>& pieces = out.kept[r];
        uint64_t held = 0;
        for (const LaunchPiece& p : pieces) held += p.last - p.first;
        if (held < 2 * granule) continue;
        const uint64_t granules = std::max<uint64_t>(
            1, uint64_t(std::llround(fraction * double(held) / double(granule))));
        uint64_t remaining = std::min(granules, held / granule - 1) * granule;
        std::vector<LaunchPiece> given;
        while (remaining > 0 && !pieces.empty()) {
            LaunchPiece& last = pieces.back();
            const uint64_t length = last.last - last.first;
            if (length <= remaining) {
                given.push_back(last);
                remaining -= length;
                pieces.pop_back();
                continue;
            }
            // Keep whole granules from the piece's start; give the rest.
            const uint64_t keep = (length - remaining + granule - 1) / granule * granule;
            if (keep < length) {
                given.push_back({last.first + keep, last.last});
                last.last = last.first + keep;
            }
            break;
        }
        std::reverse(given.begin(), given.end());  // in the order of the rank's pieces
        for (const LaunchPiece& g : given)
            for (uint64_t first = g.first; first < g.last; first += granule)
                out.shared.push_back({first, std::min(g.last, first + granule)});
        out.given[r] = std::move(given);
    }
    return out;
}

}  // namespace lucent::core

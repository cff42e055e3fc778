// One launch spread over the ranks of an MPI communicator (docs/distributed.md), the
// multi-device design (docs/multi-device.md) carried across processes: every rank holds the
// whole scene and runs the same host code (SPMD); a launch opens with an agreement (no rank
// failed, every rank's launch digest equal); the rows are taken in pieces from a counter
// shared by all ranks, each rank running its pieces on its own devices; a second agreement;
// then every rank's copy of each written buffer receives the pieces the others ran, so each
// rank's outputs hold the image of a one-process run.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <map>
#include <mutex>

#include "core/backend.h"
#include "core/launch_buffers.h"
#include "core/launch_digest.h"
#include "core/rank_group.h"
#include "core/row_balance.h"
#include "lucent/error.h"

namespace lucent::core {

namespace {

using Clock = std::chrono::steady_clock;
double ms_between(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

/// Pieces per rank: enough that the last pieces, taken while the others finish theirs,
/// are a small tail (1/16 of a rank's share), few enough that each piece keeps a rank's
/// devices busy. LUCENT_RANK_PIECES overrides it (docs/distributed.md, "Pieces").
unsigned pieces_per_rank() {
    if (const char* v = std::getenv("LUCENT_RANK_PIECES")) {
        const int n = std::atoi(v);
        if (n >= 1 && n <= 4096) return unsigned(n);
    }
    return 16;
}

/// The fraction of an index-local launch's rows that no rank keeps (SharedTail): ranks take
/// them from the counter each launch, and their elements go to every rank after it.
/// LUCENT_RANK_SHARED = a fraction (default 1/16), or 0 for none.
double shared_fraction() {
    const char* v = std::getenv("LUCENT_RANK_SHARED");
    if (!v) return 1.0 / 16;
    char* end = nullptr;
    const double f = std::strtod(v, &end);
    if (end == v || *end != '\0' || !(f >= 0 && f < 1))
        throw Error(std::string("LUCENT_RANK_SHARED='") + v +
                    "': expected a fraction from 0 to below 1 (0.0625: a sixteenth of the rows "
                    "go to whichever rank is free; 0: every row stays with a rank)");
    return f;
}

/// Index-local launches' kept rows are re-balanced from the ranks' busy times summed over
/// this many launches (enough that one launch's noise does not move rows back and forth).
constexpr unsigned kBalanceWindow = 4;

/// How far above the balanced time the slowest rank may be before rows move:
/// LUCENT_RANK_REBALANCE = a fraction (default 0.02), or "off" (rows stay where the second
/// launch put them). docs/distributed.md, "Re-balancing the kept rows".
double rebalance_threshold() {
    const char* v = std::getenv("LUCENT_RANK_REBALANCE");
    if (!v) return 0.02;
    if (std::strcmp(v, "off") == 0) return -1;
    char* end = nullptr;
    const double t = std::strtod(v, &end);
    if (end == v || *end != '\0' || !(t >= 0))
        throw Error(std::string("LUCENT_RANK_REBALANCE='") + v +
                    "': expected a fraction such as 0.02 (the slowest rank's excess over the "
                    "balanced time that moves rows) or off");
    return t;
}

/// How a launch is cut: units are rows (one-row launches: runs of 64 indices), a piece is
/// `piece_units` units (a multiple of 8 rows where there are enough: the CPU's tiles).
struct Cut {
    uint64_t unit_indices = 0, units = 0, piece_units = 1, pieces = 0;
    Cut(const LaunchSpec& spec, unsigned ranks) {
        unit_indices = spec.by_rows() ? spec.size.x : 64;
        units = (spec.count() + unit_indices - 1) / unit_indices;
        const uint64_t wanted = uint64_t(ranks) * pieces_per_rank();
        piece_units = std::max<uint64_t>(1, units / wanted);
        if (spec.by_rows() && piece_units > 8) piece_units = piece_units / 8 * 8;
        pieces = (units + piece_units - 1) / piece_units;
    }
    /// The finest cut between ranks' rows: a unit, or 8 rows where pieces are whole tiles.
    uint64_t granule(const LaunchSpec& spec) const {
        return unit_indices * (spec.by_rows() && piece_units % 8 == 0 ? 8 : 1);
    }
    LaunchPiece piece(uint64_t k, uint64_t count) const {
        const uint64_t first = k * piece_units * unit_indices;
        return {first, std::min(count, (k + 1) * piece_units * unit_indices)};
    }
};

/// Appends/reads 8-byte words of the gathered streams.
void put(std::vector<unsigned char>& out, uint64_t w) {
    const size_t at = out.size();
    out.resize(at + 8);
    std::memcpy(out.data() + at, &w, 8);
}
uint64_t get(const unsigned char*& p) {
    uint64_t w;
    std::memcpy(&w, p, 8);
    p += 8;
    return w;
}

class DistributedBackend final : public Backend {
  private:
    /// A launch's entry point and size.
    struct Key {
        unsigned entry, x, y, z;
        auto operator<=>(const Key&) const = default;
    };
    /// An index-local buffer whose elements are where the ranks computed them.
    struct Partial {
        std::shared_ptr<const Buffer> buffer;
        Key key;                          // of the launches that wrote it
        std::vector<LaunchPiece> pieces;  // this rank's
        uint64_t version = 0;             // its host contents' then
        bool kept_rows = false;           // written on the rows this rank keeps for `key`
    };
    /// The rows the ranks keep for one entry and size, and their busy times since the
    /// last re-balancing.
    struct KeptRows {
        std::vector<LaunchPiece> mine;
        std::vector<std::vector<LaunchPiece>> of_ranks;
        std::vector<LaunchPiece> shared;  // the tail no rank keeps (SharedTail)
        std::vector<double> busy_ms;      // per rank, summed over `launches`
        std::vector<uint64_t> indices;    // per rank: kept and shared, over `launches`
        unsigned launches = 0;
        std::vector<double> speed;  // per rank: indices per ms, averaged over windows
    };

  public:
    DistributedBackend(std::unique_ptr<Backend> local, std::shared_ptr<Ranks> ranks)
        : m_local(std::move(local)), m_ranks(std::move(ranks)), m_group(m_ranks->impl()) {}

    std::string name() const override {
        return std::to_string(m_group.size()) + " ranks, rank " + std::to_string(m_group.rank()) +
               " on " + m_local->name();
    }
    bool traces_on_host() const override { return m_local->traces_on_host(); }
    bool uses_host_storage() const override { return m_local->uses_host_storage(); }
    void fetch(const Buffer& buffer) override {
        // A host read of an index-local buffer whose elements are spread over the ranks:
        // collective, as every rank's host code makes the same reads (SPMD).
        auto found = m_partial.find(&buffer);
        if (found != m_partial.end()) return gather_partial(found, true);
        m_local->fetch(buffer);
    }
    std::vector<std::shared_ptr<const Buffer>> host_copies_behind() const override {
        auto behind = m_local->host_copies_behind();
        for (const auto& [raw, partial] : m_partial) behind.push_back(partial.buffer);
        return behind;
    }
    std::shared_ptr<DisplayFrame> display_frame(const Buffer& output) override {
        return m_local->display_frame(output);
    }
    void begin_launch(const CompiledScene&, const LaunchSpec&, LaunchReport&) override {
        throw Error("distributed backend: launches whole, not in pieces");
    }
    void run_piece(LaunchPiece) override {}
    void end_launch(LaunchReport&) override {}

    void launch(const CompiledScene& scene, const LaunchSpec& spec, LaunchReport& report) override {
        const unsigned ranks = unsigned(m_group.size());
        // As on several local devices: only launch-shaped outputs can be cut into pieces.
        std::vector<std::shared_ptr<const Buffer>> shaped;
        bool other = false;
        for (auto& b : launch_buffers(scene, spec.entry, &CompiledProgram::writable_buffers)) {
            if (launch_shaped(*b, spec.size))
                shaped.push_back(b);
            else
                other = true;
        }
        const Cut cut(spec, ranks);
        // A launch that writes elsewhere runs whole on every rank: each computes the same
        // (SPMD, same inputs), so no rank waits for another's copy.
        const bool split = !other && ranks > 1 && cut.pieces >= 2 * uint64_t(ranks);
        // Index-local outputs only (an accumulation): each rank keeps its rows from the
        // first such launch on, and nothing is gathered until something else reads them.
        bool sticky = split && !shaped.empty();
        for (const auto& b : shaped) sticky = sticky && b->launch_index_local();
        const Key key{spec.entry, spec.size.x, spec.size.y, spec.size.z};
        auto kept = m_kept_rows.find(key);
        const bool run_kept = sticky && kept != m_kept_rows.end();
        const bool take_from_counter = split && !run_kept;
        const bool take_shared = run_kept && !kept->second.shared.empty();
        if ((take_from_counter || take_shared) && m_group.rank() == 0)
            m_group.reset_counter();  // before anyone takes
        agree(m_group, nullptr, m_digest.of(scene, spec), "launch");
        // Elements another launch left on other ranks, which this one reads: gathered now,
        // in the order of the launch's buffers (the same on every rank).
        for (const auto& b : launch_buffers(scene, spec.entry, &CompiledProgram::buffers)) {
            auto found = m_partial.find(b.get());
            if (found == m_partial.end()) continue;
            if (found->second.version != b->version()) {  // new host contents since
                m_partial.erase(found);
                continue;
            }
            if (!(run_kept && found->second.key == key && found->second.kept_rows))
                gather_partial(found, false);
        }

        LaunchSpec local = spec;
        local.on_rows = nullptr;  // a rank's pieces are not bands of the image
        std::mutex mutex;
        std::vector<LaunchPiece> mine, mine_shared;
        size_t next_kept = 0;
        if (take_from_counter)
            local.next_piece = [&]() -> std::optional<LaunchPiece> {
                const uint64_t k = m_group.fetch_add_counter(1);
                if (k >= cut.pieces) return std::nullopt;
                const LaunchPiece piece = cut.piece(k, spec.count());
                std::lock_guard lock(mutex);
                mine.push_back(piece);
                return piece;
            };
        else if (split)  // the rows this rank keeps, then pieces of the shared tail
            local.next_piece = [&]() -> std::optional<LaunchPiece> {
                const KeptRows& rows = kept->second;
                {
                    std::lock_guard lock(mutex);
                    if (next_kept < rows.mine.size()) {
                        mine.push_back(rows.mine[next_kept]);
                        return rows.mine[next_kept++];
                    }
                }
                if (!take_shared) return std::nullopt;
                const uint64_t k = m_group.fetch_add_counter(1);
                if (k >= rows.shared.size()) return std::nullopt;
                std::lock_guard lock(mutex);
                mine.push_back(rows.shared[k]);
                mine_shared.push_back(rows.shared[k]);
                return rows.shared[k];
            };
        const auto t0 = Clock::now();
        std::string failure;
        bool failed = false;
        try {
            m_local->launch(scene, local, report);
        } catch (const std::exception& e) {
            failed = true;
            failure = e.what();
        }
        const double busy_ms = ms_between(t0, Clock::now());
        // Every rank learns whether one failed before any waits for another's pieces.
        agree(m_group, failed ? &failure : nullptr, 0, "launch");
        if (!split) return;
        const auto t_gather = Clock::now();
        if (sticky) {
            // The rows of the second launch are kept: the first one's shares include
            // warming up (a GPU's kernel compile), not the devices' speeds.
            const bool keep_now = take_from_counter && ++m_sticky_launches[key] == 2;
            std::vector<std::vector<LaunchPiece>> of_ranks;
            // The shared tail's elements reach every rank (the buffers' elements this rank
            // kept are already current on its devices: fetched locally, not gathered).
            exchange(mine, mine_shared, busy_ms, spec,
                     take_shared ? shaped : std::vector<std::shared_ptr<const Buffer>>{}, report,
                     true, &of_ranks);
            if (keep_now) keep_rows(key, cut.granule(spec), spec, shaped, std::move(of_ranks));
            if (run_kept) balance_kept_rows(key, cut.granule(spec), spec, shaped, report);
            for (const auto& b : shaped) {
                b->mark_device_newer();  // a host read gathers it (fetch)
                m_partial[b.get()] =
                    Partial{b, key, mine, b->version(), run_kept || m_kept_rows.count(key)};
            }
        } else {
            exchange(mine, mine, busy_ms, spec, shaped, report, false);
        }
        report.gather_ms = ms_between(t_gather, Clock::now());
        trace(spec,
              take_shared ? "index-local, rows kept and a shared tail"
              : run_kept  ? "index-local, rows kept"
              : sticky    ? "index-local, pieces"
                          : "pieces",
              report);
    }

  private:
    /// The second index-local launch of an entry and size: each rank keeps the rows it ran
    /// (`of_ranks`: every rank's), less its part of the shared tail where every rank's
    /// elements live on the host (CPU ranks: the tail's elements go to every rank after
    /// each launch, which on a GPU would cost a download and an upload of the buffers).
    void keep_rows(const Key& key, uint64_t granule, const LaunchSpec& spec,
                   const std::vector<std::shared_ptr<const Buffer>>& shaped,
                   std::vector<std::vector<LaunchPiece>> of_ranks) {
        KeptRows& kept = m_kept_rows[key];
        const auto rank = size_t(m_group.rank());
        const auto host = m_group.all_gather_words({m_local->uses_host_storage() ? 1u : 0u, 0});
        bool all_host = m_shared_fraction > 0;
        for (const auto& words : host) all_host = all_host && words[0] == 1;
        if (!all_host) {
            kept.mine = of_ranks[rank];
            kept.of_ranks = std::move(of_ranks);
            return;
        }
        SharedTail tail = share_tail(of_ranks, m_shared_fraction, granule);
        LaunchReport ignored;
        exchange(tail.given[rank], tail.given[rank], 0, spec, shaped, ignored, true);
        kept.mine = tail.kept[rank];
        kept.of_ranks = std::move(tail.kept);
        kept.shared = std::move(tail.shared);
    }

    /// After a launch on the kept rows: every kBalanceWindow such launches, the ranks'
    /// shares follow their measured speeds (balance_rows; the same answer on every rank,
    /// from the gathered busy times), and the elements of the rows that change owner move
    /// to their new rank, so each pixel's accumulation goes on where its frames were added.
    void balance_kept_rows(const Key& key, uint64_t granule, const LaunchSpec& spec,
                           const std::vector<std::shared_ptr<const Buffer>>& shaped,
                           const LaunchReport& report) {
        if (m_rebalance_threshold < 0) return;
        KeptRows& kept = m_kept_rows[key];
        kept.busy_ms.resize(report.ranks.size(), 0.0);
        kept.indices.resize(report.ranks.size(), 0);
        for (size_t r = 0; r < report.ranks.size(); ++r) {
            kept.busy_ms[r] += report.ranks[r].busy_ms;
            kept.indices[r] += report.ranks[r].indices;
        }
        if (++kept.launches < kBalanceWindow) return;
        // Each window's speeds, averaged with the earlier windows' (an exponential average
        // of weight 1/2): ranks sharing a machine's cores run at speeds that wander by a
        // few percent from window to window, and following each window alone would move
        // rows back and forth after the noise. The balance is of the times the averaged
        // speeds give for the rows each rank holds.
        const size_t ranks = kept.of_ranks.size();
        kept.speed.resize(ranks, 0.0);
        std::vector<double> expected_ms(ranks, 0.0);
        for (size_t r = 0; r < ranks && r < kept.busy_ms.size(); ++r) {
            uint64_t held = 0;
            for (const LaunchPiece& p : kept.of_ranks[r]) held += p.last - p.first;
            if (held == 0 || kept.indices[r] == 0 || !(kept.busy_ms[r] > 0)) continue;
            // Indices run (kept and shared) per ms: a rank that took more of the tail
            // was busier for it, not slower.
            const double speed = double(kept.indices[r]) / kept.busy_ms[r];
            kept.speed[r] = kept.speed[r] > 0 ? 0.5 * (kept.speed[r] + speed) : speed;
            expected_ms[r] = double(held) / kept.speed[r];
        }
        kept.busy_ms.assign(kept.busy_ms.size(), 0.0);
        kept.indices.assign(kept.indices.size(), 0);
        kept.launches = 0;
        const RowBalance balance =
            balance_rows(kept.of_ranks, expected_ms, granule, m_rebalance_threshold);
        if (!balance.moved) return;
        const auto rank = size_t(m_group.rank());
        // The given rows' elements reach every rank (the new owner among them); a GPU
        // rank's come from its device first (as in a host read: not through the buffer).
        LaunchReport ignored;
        exchange(balance.given[rank], balance.given[rank], 0, spec, shaped, ignored, true);
        kept.mine = balance.kept[rank];
        if (m_trace && rank == 0) {
            std::fprintf(
                stderr,
                "distributed: entry %u, kept rows re-balanced (at the averaged speeds the slowest "
                "rank takes %.3fx the balanced time):",
                spec.entry, balance.imbalance);
            for (size_t r = 0; r < balance.kept.size(); ++r) {
                uint64_t before = 0, after = 0;
                for (const LaunchPiece& p : kept.of_ranks[r]) before += p.last - p.first;
                for (const LaunchPiece& p : balance.kept[r]) after += p.last - p.first;
                std::fprintf(stderr, " [rank %zu: %llu -> %llu indices]", r,
                             (unsigned long long)before, (unsigned long long)after);
            }
            std::fprintf(stderr, "\n");
        }
        kept.of_ranks = balance.kept;
    }

    /// The elements an index-local buffer's last launches left on each rank reach every
    /// rank (`in_fetch`: inside a host read, whose flag is already cleared).
    void gather_partial(std::map<const Buffer*, Partial>::iterator found, bool in_fetch) {
        const Partial partial = found->second;
        m_partial.erase(found);
        LaunchReport ignored;
        LaunchSpec spec;
        spec.size = uint3{partial.key.x, partial.key.y, partial.key.z};
        exchange(partial.pieces, partial.pieces, 0, spec, {partial.buffer}, ignored, in_fetch);
    }

    /// Every rank sends its busy time, its exceptions, the ranges of the pieces it ran and
    /// of those it sends, then each buffer's bytes of each piece sent, to every other;
    /// each writes the others' pieces into its host copies (sending every piece ran: the
    /// one-process image on every rank).
    /// `ran`: the pieces this rank ran (reported); `sent`: those whose elements of `shaped`
    /// it sends. `fetch_locally`: a GPU rank's pieces come from its device directly, not
    /// through the buffer (inside a host read, whose flag is already cleared, or for a
    /// buffer whose host read would gather it). `of_ranks` (if given) receives every
    /// rank's `ran`.
    void exchange(const std::vector<LaunchPiece>& ran, const std::vector<LaunchPiece>& sent,
                  double busy_ms, const LaunchSpec& spec,
                  const std::vector<std::shared_ptr<const Buffer>>& shaped, LaunchReport& report,
                  bool fetch_locally, std::vector<std::vector<LaunchPiece>>* of_ranks = nullptr) {
        const uint3 size = spec.size;
        auto linear = [&](uint3 i) { return (uint64_t(i.z) * size.y + i.y) * size.x + i.x; };
        std::vector<unsigned char>& out = m_send;
        out.clear();
        double busy = busy_ms;
        uint64_t busy_bits;
        std::memcpy(&busy_bits, &busy, 8);
        put(out, busy_bits);
        put(out, report.exceptions.size());
        for (const auto& [code, e] : report.exceptions) {
            put(out, uint64_t(int64_t(code)));
            put(out, e.count);
            put(out, linear(e.first_index));
        }
        for (const auto* pieces : {&ran, &sent}) {
            put(out, pieces->size());
            for (const LaunchPiece& p : *pieces) {
                put(out, p.first);
                put(out, p.last);
            }
        }
        for (const auto& b : shaped) {
            // A GPU rank's pieces reach its host copy.
            if (fetch_locally)
                m_local->fetch(*b);
            else
                b->sync_from_device();
            const size_t element = b->element().size;
            const auto* bytes = static_cast<const unsigned char*>(b->raw());
            for (const LaunchPiece& p : sent)
                out.insert(out.end(), bytes + p.first * element, bytes + p.last * element);
        }
        std::vector<uint64_t> counts;
        m_group.all_gather_bytes(out, m_received, counts);

        report.exceptions.clear();
        report.ranks.assign(counts.size(), {});
        const unsigned char* p = m_received.data();
        for (int r = 0; r < int(counts.size()); ++r) {
            const unsigned char* end = p + counts[size_t(r)];
            LaunchReport::RankShare& share = report.ranks[size_t(r)];
            const uint64_t bits = get(p);
            std::memcpy(&share.busy_ms, &bits, 8);
            for (uint64_t n = get(p); n > 0; --n) {
                const int code = int(int64_t(get(p)));
                const uint64_t count = get(p), first = get(p);
                const uint3 index{unsigned(first % size.x), unsigned(first / size.x % size.y),
                                  unsigned(first / (uint64_t(size.x) * size.y))};
                auto [it, fresh] = report.exceptions.try_emplace(code);
                if (fresh || first < linear(it->second.first_index)) it->second.first_index = index;
                it->second.count += count;
            }
            auto read_pieces = [&] {
                std::vector<LaunchPiece> pieces(get(p));
                for (LaunchPiece& piece : pieces) {
                    piece.first = get(p);
                    piece.last = get(p);
                }
                return pieces;
            };
            std::vector<LaunchPiece> its_ran = read_pieces();
            const std::vector<LaunchPiece> its_sent = read_pieces();
            for (const LaunchPiece& piece : its_ran) share.indices += piece.last - piece.first;
            share.pieces = unsigned(its_ran.size());
            if (of_ranks) of_ranks->push_back(std::move(its_ran));
            for (const auto& b : shaped) {
                const size_t element = b->element().size;
                auto* bytes = static_cast<unsigned char*>(const_cast<Buffer&>(*b).raw());
                for (const LaunchPiece& piece : its_sent) {
                    const size_t n = (piece.last - piece.first) * element;
                    if (r != m_group.rank()) std::memcpy(bytes + piece.first * element, p, n);
                    p += n;
                }
            }
            if (p != end)
                throw Error("distributed backend: rank " + std::to_string(r) +
                            "'s gathered pieces do not add up (internal error)");
        }
        // New host contents on every rank alike: a GPU uploads them before it next reads
        // them, and the versions (which launch digests do not hash) stay equal across ranks.
        for (const auto& b : shaped) const_cast<Buffer&>(*b).unmap();
    }

    void trace(const LaunchSpec& spec, const char* how, const LaunchReport& report) const {
        if (!m_trace || m_group.rank() != 0) return;
        std::fprintf(
            stderr,
            "distributed: entry %u, %llu indices, %s, gather %.3f ms of %zu bytes:", spec.entry,
            (unsigned long long)spec.count(), how, report.gather_ms, m_received.size());
        for (size_t r = 0; r < report.ranks.size(); ++r)
            std::fprintf(stderr, " [rank %zu: %u pieces %llu indices %.3f ms]", r,
                         report.ranks[r].pieces, (unsigned long long)report.ranks[r].indices,
                         report.ranks[r].busy_ms);
        std::fprintf(stderr, "\n");
    }

    std::unique_ptr<Backend> m_local;
    std::shared_ptr<Ranks> m_ranks;
    std::map<Key, KeptRows> m_kept_rows;        // per entry and size
    std::map<Key, unsigned> m_sticky_launches;  // index-local launches taken so far
    std::map<const Buffer*, Partial> m_partial;
    Ranks::Impl& m_group;
    LaunchDigest m_digest;
    std::vector<unsigned char> m_send, m_received;  // kept: a 4K image's pieces each launch
    const bool m_trace = std::getenv("LUCENT_MULTI_TRACE") != nullptr;
    const double m_rebalance_threshold = rebalance_threshold();
    const double m_shared_fraction = shared_fraction();
};

}  // namespace

std::unique_ptr<Backend> make_distributed_backend(std::unique_ptr<Backend> local,
                                                  std::shared_ptr<Ranks> ranks) {
    return std::make_unique<DistributedBackend>(std::move(local), std::move(ranks));
}

}  // namespace lucent::core

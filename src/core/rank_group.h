// What the core asks of a group of ranks (lucent::Ranks): a few collectives and one
// shared piece counter. Two implementations, chosen at configure time: MPI
// (src/mpi/mpi_ranks.cpp, LUCENT_MPI) and this process alone (single_rank.cpp, every build).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lucent/ranks.h"

namespace lucent {

struct Ranks::Impl {
    virtual ~Impl() = default;
    virtual int rank() const = 0;
    virtual int size() const = 0;
    /// Collective: every rank's `words`, in rank order.
    virtual std::vector<std::array<uint64_t, 2>> all_gather_words(
        std::array<uint64_t, 2> words) = 0;
    /// Collective: `root`'s text, on every rank.
    virtual std::string broadcast_text(int root, const std::string& text) = 0;
    /// Collective: every rank's bytes, concatenated in rank order; `counts` gets each
    /// rank's byte count.
    virtual void all_gather_bytes(const std::vector<unsigned char>& mine,
                                  std::vector<unsigned char>& all,
                                  std::vector<uint64_t>& counts) = 0;
    /// The launch's shared piece counter on rank 0. reset: rank 0 only, before the
    /// agreement that opens a launch (so no rank takes a piece before it); take: adds `n`
    /// and returns the value before, from any thread of any rank.
    virtual void reset_counter() = 0;
    virtual uint64_t fetch_add_counter(uint64_t n) = 0;
};

namespace core {

/// This process alone: rank 0 of 1, the counter a local atomic.
std::unique_ptr<Ranks::Impl> make_single_rank();
#if LUCENT_HAVE_MPI
/// The ranks of MPI_COMM_WORLD (MPI initialised if need be).
std::unique_ptr<Ranks::Impl> make_mpi_world();
#endif

/// The agreement every launch opens with (docs/distributed.md, "Divergence and faults"):
/// each rank contributes whether it failed (its message) and the digest of the launch it
/// is about to run. Throws RankError on every rank if a rank failed ("rank R: ...") or the
/// digests differ (naming the ranks whose launch differs from rank 0's).
void agree(Ranks::Impl& ranks, const std::string* failure, uint64_t digest, const char* what);

}  // namespace core
}  // namespace lucent

// Processes that render together (docs/distributed.md): the ranks of an MPI communicator.
// A Context given a Ranks (ContextOptions::ranks) spreads each launch over every rank's
// devices; every rank runs the same host code (SPMD), and each launch checks that they did.
#pragma once

#include <memory>
#include <string>

#include "lucent/error.h"

namespace lucent {

/// A rank failed (an error on one rank, or ranks whose launches differ), as every rank
/// learns it at the same point: the message names the rank and the cause.
class RankError : public Error {
  public:
    RankError(int failed_rank, const std::string& message)
        : Error(message), m_failed_rank(failed_rank) {}
    /// The rank that failed first (the lowest), or -1 when ranks diverged.
    int failed_rank() const { return m_failed_rank; }

  private:
    int m_failed_rank;
};

class Ranks {
  public:
    /// Whether this build of Lucent has MPI (Open MPI at configure time, LUCENT_MPI).
    static bool built_with_mpi();
    /// Whether a launcher (mpirun, srun with PMIx) started this process as one of several.
    static bool launched_as_rank();
    /// The ranks of MPI_COMM_WORLD (MPI is initialised here if it is not yet, and
    /// finalised at exit). Throws Error in a build without MPI when launched_as_rank().
    /// Without a launcher, and in a build without MPI: a group of this process alone.
    static std::shared_ptr<Ranks> world();

    ~Ranks();
    Ranks(const Ranks&) = delete;
    Ranks& operator=(const Ranks&) = delete;

    int rank() const;
    int size() const;
    /// An agreement point: every rank must call it at the same place. A rank that passes
    /// its failure (what() of the error it caught) makes every rank throw RankError
    /// "rank R: <failure>" (R the lowest failing rank); with none it returns. Call it where
    /// a rank may have failed outside a launch (a scene file missing on one node), so the
    /// others do not wait for it in the next launch.
    void agree(const std::string* failure = nullptr);

    struct Impl;
    Impl& impl() { return *m_impl; }
    explicit Ranks(std::unique_ptr<Impl> impl);

  private:
    std::unique_ptr<Impl> m_impl;
};

}  // namespace lucent

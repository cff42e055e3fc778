// `mpirun -np N lucent render|bench igi ...`: the CLI as one of several ranks
// (docs/distributed.md, docs/cli.md). No flag: a launcher's environment is enough.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "lucent/ranks.h"

namespace lucent::cli {

/// Under a launcher: joins the ranks of MPI_COMM_WORLD (once) and silences stdout on every
/// rank but 0, which alone prints and writes. Not under a launcher: null. Throws Error in a
/// build without MPI started by mpirun.
std::shared_ptr<Ranks> join_ranks();

/// The launcher's rank of this process from its environment (0 without a launcher), known
/// before MPI is initialised: errors every rank meets alike are printed by rank 0 alone.
int launcher_rank();

/// Runs `work` on every rank; a rank's error (a scene file missing on one node) becomes
/// every rank's RankError "rank R: ..." at the agreement that follows, so no rank waits for
/// a failed one. Without ranks: runs `work`.
void run_agreed(const std::shared_ptr<Ranks>& ranks, const std::function<void()>& work);

}  // namespace lucent::cli

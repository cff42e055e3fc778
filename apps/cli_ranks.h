// `mpirun -np N lucent render|bench igi ...`: the CLI as one of several ranks
// (docs/distributed.md, docs/cli.md). No flag: a launcher's environment is enough.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "lucent/ranks.h"
#include "lucent/run_agreed.h"

namespace lucent::cli {

/// Under a launcher: joins the ranks of MPI_COMM_WORLD (once) and silences stdout on every
/// rank but 0, which alone prints and writes. Not under a launcher: null. Throws Error in a
/// build without MPI started by mpirun.
std::shared_ptr<Ranks> join_ranks();

/// The launcher's rank of this process from its environment (0 without a launcher), known
/// before MPI is initialised: errors every rank meets alike are printed by rank 0 alone.
int launcher_rank();

}  // namespace lucent::cli

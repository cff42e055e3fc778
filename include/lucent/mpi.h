// A Context spanning the ranks of your own MPI communicator (builds with LUCENT_MPI; link
// Lucent::lucent, which brings MPI::MPI_CXX). Ranks::world() covers MPI_COMM_WORLD.
#pragma once

#include <mpi.h>

#include <memory>

#include "lucent/ranks.h"

namespace lucent {

/// The ranks of `comm` (duplicated: Lucent's messages never mix with yours). MPI must be
/// initialised with MPI_THREAD_SERIALIZED or more. Collective over `comm`.
std::shared_ptr<Ranks> ranks_of(MPI_Comm comm);

}  // namespace lucent

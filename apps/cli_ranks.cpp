// The CLI's side of distributed rendering: which rank prints, and where ranks agree.
#include "cli_ranks.h"

#include <cstdio>
#include <cstdlib>
#include <exception>

namespace lucent::cli {

std::shared_ptr<Ranks> join_ranks() {
    static std::shared_ptr<Ranks> ranks;
    if (ranks || !Ranks::launched_as_rank()) return ranks;
    ranks = Ranks::world();
    // Rank 0 prints the report and writes the image; the others' output would repeat it.
    if (ranks->rank() != 0 && !std::freopen("/dev/null", "w", stdout))
        throw Error("rank " + std::to_string(ranks->rank()) + ": cannot silence stdout");
    return ranks;
}

int launcher_rank() {
    for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"})
        if (const char* value = std::getenv(name)) return std::atoi(value);
    return 0;
}

}  // namespace lucent::cli

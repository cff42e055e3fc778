// lucent::Ranks: the group of processes a Context may span, and the agreement every rank
// reaches before a launch (docs/distributed.md).
#include <cstdlib>

#include "core/rank_group.h"

namespace lucent {

Ranks::Ranks(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
Ranks::~Ranks() = default;

int Ranks::rank() const {
    return m_impl->rank();
}
int Ranks::size() const {
    return m_impl->size();
}

void Ranks::agree(const std::string* failure) {
    core::agree(*m_impl, failure, 0, "agreement");
}

bool Ranks::built_with_mpi() {
#if LUCENT_HAVE_MPI
    return true;
#else
    return false;
#endif
}

bool Ranks::launched_as_rank() {
    // Open MPI's mpirun sets OMPI_COMM_WORLD_SIZE; PMIx launchers (srun, prterun) PMIX_RANK.
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
        if (std::getenv(name)) return true;
    return false;
}

std::shared_ptr<Ranks> Ranks::world() {
    if (!launched_as_rank()) return std::make_shared<Ranks>(core::make_single_rank());
#if LUCENT_HAVE_MPI
    return std::make_shared<Ranks>(core::make_mpi_world());
#else
    throw Error(
        "Ranks: this process was started by an MPI launcher (mpirun), but this build of Lucent "
        "has no MPI; install libopenmpi-dev and configure again (LUCENT_MPI), or run without "
        "mpirun");
#endif
}

namespace core {

void agree(Ranks::Impl& ranks, const std::string* failure, uint64_t digest, const char* what) {
    // One collective for both questions: [failed?, digest] from every rank.
    const auto all = ranks.all_gather_words({failure ? 1u : 0u, digest});
    for (int r = 0; r < int(all.size()); ++r)
        if (all[size_t(r)][0]) {
            const std::string text = ranks.broadcast_text(r, failure ? *failure : std::string());
            throw RankError(r, "rank " + std::to_string(r) + ": " + text);
        }
    std::string differ;
    for (int r = 1; r < int(all.size()); ++r)
        if (all[size_t(r)][1] != all[0][1])
            differ += (differ.empty() ? "" : ", ") + std::to_string(r);
    if (!differ.empty())
        throw RankError(-1, std::string("ranks diverged: the ") + what + " of rank" +
                                (differ.find(',') == std::string::npos ? " " : "s ") + differ +
                                " differs from rank 0's (entry point, launch size, variables, "
                                "buffer contents or scene graph); every rank must run the same "
                                "host code on the same inputs (docs/distributed.md)");
}

}  // namespace core
}  // namespace lucent

// The ranks of an MPI communicator (Open MPI from Debian): the collectives of
// core/rank_group.h, and the launch's piece counter as an MPI-3 one-sided window on rank 0
// that every rank updates with MPI_Fetch_and_op under a passive-target epoch
// (MPI_Win_lock_all), so no rank serves pieces (docs/distributed.md, "Pieces").
#include <mpi.h>

#include <climits>
#include <cstdlib>
#include <mutex>

#include "core/rank_group.h"
#include "lucent/mpi.h"

namespace lucent::core {

namespace {

void check(int code, const char* call) {
    if (code == MPI_SUCCESS) return;
    char text[MPI_MAX_ERROR_STRING];
    int length = 0;
    MPI_Error_string(code, text, &length);
    throw Error(std::string("MPI: ") + call + " failed: " + std::string(text, size_t(length)));
}

/// MPI is initialised by the first group made here and finalised at exit; a program that
/// initialised MPI itself finalises it itself.
bool g_initialised_here = false;

void finalize_at_exit() {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
}

void initialise() {
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (initialised) return;
    // Several device threads of a rank take pieces: calls are serialised by a mutex.
    int provided = 0;
    check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided), "MPI_Init_thread");
    if (provided < MPI_THREAD_SERIALIZED)
        throw Error("MPI: this MPI library gives thread level " + std::to_string(provided) +
                    "; Lucent needs MPI_THREAD_SERIALIZED");
    g_initialised_here = true;
    std::atexit(finalize_at_exit);
}

class MpiRanks final : public Ranks::Impl {
  public:
    explicit MpiRanks(MPI_Comm comm) {
        check(MPI_Comm_dup(comm, &m_comm), "MPI_Comm_dup");  // our messages apart from the user's
        MPI_Comm_rank(m_comm, &m_rank);
        MPI_Comm_size(m_comm, &m_size);
        const MPI_Aint bytes = m_rank == 0 ? MPI_Aint(sizeof(uint64_t)) : 0;
        check(MPI_Win_allocate(bytes, sizeof(uint64_t), MPI_INFO_NULL, m_comm, &m_counter_base,
                               &m_counter),
              "MPI_Win_allocate");
        if (m_rank == 0) *m_counter_base = 0;
        MPI_Barrier(m_comm);  // the counter is zero before any rank locks it
        check(MPI_Win_lock_all(MPI_MODE_NOCHECK, m_counter), "MPI_Win_lock_all");
    }
    ~MpiRanks() override {
        int finalized = 0;
        MPI_Finalized(&finalized);
        if (finalized) return;
        MPI_Win_unlock_all(m_counter);
        MPI_Win_free(&m_counter);
        MPI_Comm_free(&m_comm);
    }

    int rank() const override { return m_rank; }
    int size() const override { return m_size; }

    std::vector<std::array<uint64_t, 2>> all_gather_words(std::array<uint64_t, 2> words) override {
        std::lock_guard lock(m_mutex);
        std::vector<std::array<uint64_t, 2>> all(static_cast<size_t>(m_size));
        check(MPI_Allgather(words.data(), 2, MPI_UINT64_T, all.data(), 2, MPI_UINT64_T, m_comm),
              "MPI_Allgather");
        return all;
    }

    std::string broadcast_text(int root, const std::string& text) override {
        std::lock_guard lock(m_mutex);
        uint64_t length = text.size();
        check(MPI_Bcast(&length, 1, MPI_UINT64_T, root, m_comm), "MPI_Bcast");
        std::string out = m_rank == root ? text : std::string(length, '\0');
        check(MPI_Bcast(out.data(), int(length), MPI_CHAR, root, m_comm), "MPI_Bcast");
        return out;
    }

    void all_gather_bytes(const std::vector<unsigned char>& mine, std::vector<unsigned char>& all,
                          std::vector<uint64_t>& counts) override {
        std::lock_guard lock(m_mutex);
        counts.assign(size_t(m_size), 0);
        const uint64_t my_count = mine.size();
        check(MPI_Allgather(&my_count, 1, MPI_UINT64_T, counts.data(), 1, MPI_UINT64_T, m_comm),
              "MPI_Allgather");
        std::vector<int> int_counts(static_cast<size_t>(m_size)),
            displacements(static_cast<size_t>(m_size));
        uint64_t total = 0;
        for (int r = 0; r < m_size; ++r) {
            displacements[size_t(r)] = int(total);
            int_counts[size_t(r)] = int(counts[size_t(r)]);
            total += counts[size_t(r)];
        }
        // Every rank computed the same total: all throw together or none.
        if (total > uint64_t(INT_MAX))
            throw Error("MPI: a launch's gathered outputs are " + std::to_string(total) +
                        " bytes, more than one MPI_Allgatherv carries (2 GiB); launch smaller "
                        "images or fewer output buffers per launch");
        all.resize(total);
        check(MPI_Allgatherv(mine.data(), int(my_count), MPI_BYTE, all.data(), int_counts.data(),
                             displacements.data(), MPI_BYTE, m_comm),
              "MPI_Allgatherv");
    }

    void reset_counter() override {
        std::lock_guard lock(m_mutex);
        uint64_t zero = 0, old = 0;
        check(MPI_Fetch_and_op(&zero, &old, MPI_UINT64_T, 0, 0, MPI_REPLACE, m_counter),
              "MPI_Fetch_and_op");
        check(MPI_Win_flush(0, m_counter), "MPI_Win_flush");
    }

    uint64_t fetch_add_counter(uint64_t n) override {
        std::lock_guard lock(m_mutex);
        uint64_t old = 0;
        check(MPI_Fetch_and_op(&n, &old, MPI_UINT64_T, 0, 0, MPI_SUM, m_counter),
              "MPI_Fetch_and_op");
        check(MPI_Win_flush(0, m_counter), "MPI_Win_flush");
        return old;
    }

  private:
    MPI_Comm m_comm = MPI_COMM_NULL;
    int m_rank = 0, m_size = 1;
    uint64_t* m_counter_base = nullptr;
    MPI_Win m_counter = MPI_WIN_NULL;
    std::mutex m_mutex;  // MPI_THREAD_SERIALIZED: one call at a time
};

}  // namespace

std::unique_ptr<Ranks::Impl> make_mpi_world() {
    initialise();
    return std::make_unique<MpiRanks>(MPI_COMM_WORLD);
}

}  // namespace lucent::core

namespace lucent {

std::shared_ptr<Ranks> ranks_of(MPI_Comm comm) {
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (!initialised)
        throw Error(
            "ranks_of: MPI is not initialised; call MPI_Init_thread (with "
            "MPI_THREAD_SERIALIZED or more) first, or use Ranks::world()");
    int level = 0;
    MPI_Query_thread(&level);
    if (level < MPI_THREAD_SERIALIZED)
        throw Error("ranks_of: MPI was initialised with thread level " + std::to_string(level) +
                    "; a rank's devices take pieces from several threads: initialise it with "
                    "MPI_Init_thread(..., MPI_THREAD_SERIALIZED, ...) or more");
    return std::make_shared<Ranks>(std::make_unique<core::MpiRanks>(comm));
}

}  // namespace lucent

// lucent-ranks-bench: what distributed launches cost in MPI, measured between the ranks it
// runs on (docs/distributed.md, "Model"): point-to-point latency and bandwidth (rank 0 and
// the last rank, ping-pong), the piece counter's MPI_Fetch_and_op (every rank at once, as
// in a launch), the agreement's MPI_Allgather of 16 bytes, and the all-gather of a
// float4 image split evenly over the ranks (a launch's outputs at 1920x1080 and 3840x2160).
//
//   mpirun -np 2 lucent-ranks-bench            (prints a table on rank 0)
#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <vector>

namespace {

double now() {
    return MPI_Wtime();
}

/// Half the round trip of `bytes` between rank 0 and `peer`, best of `repeats` (seconds).
double ping_pong(int rank, int peer, size_t bytes, int repeats) {
    std::vector<unsigned char> buffer(std::max<size_t>(bytes, 1));
    double best = 1e30;
    for (int i = 0; i < repeats; ++i) {
        MPI_Barrier(MPI_COMM_WORLD);
        const double t0 = now();
        if (rank == 0) {
            MPI_Send(buffer.data(), int(bytes), MPI_BYTE, peer, 0, MPI_COMM_WORLD);
            MPI_Recv(buffer.data(), int(bytes), MPI_BYTE, peer, 0, MPI_COMM_WORLD,
                     MPI_STATUS_IGNORE);
        } else if (rank == peer) {
            MPI_Recv(buffer.data(), int(bytes), MPI_BYTE, 0, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            MPI_Send(buffer.data(), int(bytes), MPI_BYTE, 0, 0, MPI_COMM_WORLD);
        }
        best = std::min(best, (now() - t0) / 2);
    }
    MPI_Bcast(&best, 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    return best;
}

/// Mean seconds per MPI_Fetch_and_op + flush on rank 0's counter, every rank at once.
double fetch_and_op(int ranks, int count) {
    uint64_t* base = nullptr;
    MPI_Win win;
    int rank;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Win_allocate(rank == 0 ? sizeof(uint64_t) : 0, sizeof(uint64_t), MPI_INFO_NULL,
                     MPI_COMM_WORLD, &base, &win);
    if (rank == 0) *base = 0;
    MPI_Barrier(MPI_COMM_WORLD);
    MPI_Win_lock_all(MPI_MODE_NOCHECK, win);
    const uint64_t one = 1;
    uint64_t old = 0;
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = now();
    for (int i = 0; i < count; ++i) {
        MPI_Fetch_and_op(&one, &old, MPI_UINT64_T, 0, 0, MPI_SUM, win);
        MPI_Win_flush(0, win);
    }
    double mine = (now() - t0) / count, mean = 0;
    MPI_Win_unlock_all(win);
    MPI_Win_free(&win);
    MPI_Allreduce(&mine, &mean, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    return mean / ranks;
}

/// Best seconds of an MPI_Allgather of two 64-bit words per rank (a launch's agreement).
double agreement(int ranks, int repeats) {
    uint64_t words[2] = {0, 0};
    std::vector<uint64_t> all(2 * size_t(ranks));
    double best = 1e30;
    for (int i = 0; i < repeats; ++i) {
        MPI_Barrier(MPI_COMM_WORLD);
        const double t0 = now();
        MPI_Allgather(words, 2, MPI_UINT64_T, all.data(), 2, MPI_UINT64_T, MPI_COMM_WORLD);
        best = std::min(best, now() - t0);
    }
    MPI_Allreduce(MPI_IN_PLACE, &best, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    return best;
}

/// Best seconds of an MPI_Allgatherv of `bytes` split evenly over the ranks.
double gather_image(int ranks, size_t bytes, int repeats) {
    const size_t share = bytes / size_t(ranks);
    std::vector<unsigned char> mine(share, 1), all(share * size_t(ranks));
    std::vector<int> counts(static_cast<size_t>(ranks), int(share));
    std::vector<int> displacements(static_cast<size_t>(ranks));
    for (int r = 0; r < ranks; ++r) displacements[size_t(r)] = int(share * size_t(r));
    double best = 1e30;
    for (int i = 0; i < repeats; ++i) {
        MPI_Barrier(MPI_COMM_WORLD);
        const double t0 = now();
        MPI_Allgatherv(mine.data(), int(share), MPI_BYTE, all.data(), counts.data(),
                       displacements.data(), MPI_BYTE, MPI_COMM_WORLD);
        best = std::min(best, now() - t0);
    }
    MPI_Allreduce(MPI_IN_PLACE, &best, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    return best;
}

}  // namespace

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    int rank = 0, ranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    if (ranks < 2) {
        if (rank == 0)
            std::fprintf(stderr, "lucent-ranks-bench: run it under mpirun -np 2 or more\n");
        MPI_Finalize();
        return 2;
    }
    const int peer = ranks - 1;
    const bool print = rank == 0;
    if (print) std::printf("lucent-ranks-bench: %d ranks\n", ranks);
    for (size_t bytes :
         {size_t(8), size_t(64) << 10, size_t(1) << 20, size_t(16) << 20, size_t(128) << 20}) {
        const double s = ping_pong(rank, peer, bytes, bytes > (1u << 20) ? 5 : 200);
        if (print)
            std::printf("  ping-pong %10zu B: %10.2f us one way, %8.2f GB/s\n", bytes, s * 1e6,
                        double(bytes) / s / 1e9);
    }
    const double fop = fetch_and_op(ranks, 2000);
    if (print) std::printf("  MPI_Fetch_and_op + flush (all ranks at once): %.2f us\n", fop * 1e6);
    const double agree = agreement(ranks, 200);
    if (print) std::printf("  agreement (MPI_Allgather of 16 B): %.2f us\n", agree * 1e6);
    for (auto [w, h] : {std::pair{1920u, 1080u}, std::pair{3840u, 2160u}}) {
        const size_t bytes = size_t(w) * h * 16;
        const double s = gather_image(ranks, bytes, 3);
        if (print)
            std::printf(
                "  all-gather of a %ux%u float4 image (%.1f MB): %.2f ms, %.2f GB/s per rank\n", w,
                h, double(bytes) / 1e6, s * 1e3, double(bytes) * (ranks - 1) / ranks / s / 1e9);
    }
    MPI_Finalize();
    return 0;
}

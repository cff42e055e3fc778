// The CPU backend's thread pool: each job runs once on each worker it asks for, a pool too
// large is refused, and a pool the system cannot give every thread throws instead of
// deadlocking (the threads already started are stopped and joined).
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "cpu/thread_pool.h"
#include "lucent/error.h"

namespace {

using lucent::cpu::ThreadPool;

TEST(ThreadPool, EachJobRunsOnceOnEveryWorkerItAsksFor) {
    ThreadPool pool(8);
    ASSERT_EQ(pool.size(), 8u);
    std::vector<std::atomic<unsigned>> runs(8);
    for (int job = 0; job < 500; ++job) pool.run([&](unsigned w) { ++runs[w]; });
    for (unsigned w = 0; w < 8; ++w) EXPECT_EQ(runs[w].load(), 500u) << "worker " << w;
    // A job for three workers wakes only 0, 1 and 2.
    for (auto& r : runs) r = 0;
    pool.run([&](unsigned w) { ++runs[w]; }, 3);
    for (unsigned w = 0; w < 8; ++w) EXPECT_EQ(runs[w].load(), w < 3 ? 1u : 0u) << "worker " << w;
}

TEST(ThreadPool, AnExceptionInAJobReachesTheCallerAndThePoolRunsOn) {
    ThreadPool pool(4);
    EXPECT_THROW(pool.run([](unsigned w) {
        if (w == 2) throw std::runtime_error("worker 2 failed");
    }),
                 std::runtime_error);
    std::atomic<unsigned> total{0};
    pool.run([&](unsigned) { ++total; });
    EXPECT_EQ(total.load(), 4u);
}

TEST(ThreadPool, MoreThreadsThanTheLimitAreRefused) {
    try {
        ThreadPool pool(ThreadPool::kMaxThreads + 1);
        FAIL() << "a pool of " << ThreadPool::kMaxThreads + 1 << " threads was made";
    } catch (const lucent::Error& e) {
        EXPECT_NE(std::string(e.what()).find(std::to_string(ThreadPool::kMaxThreads)),
                  std::string::npos)
            << e.what();
    }
}

/// In a child process whose address space cannot hold 400 thread stacks (8 MB each): exits
/// with 0 when the pool throws, 3 when every thread started. An alarm turns a deadlock (what
/// the pool used to do: wait forever on the workers it had started) into a failure.
[[noreturn]] void make_a_pool_too_large_for_memory() {
    ::alarm(30);
    const rlimit limit{300u << 20, 300u << 20};
    ::setrlimit(RLIMIT_AS, &limit);
    try {
        ThreadPool pool(400);
        std::fprintf(stderr, "all 400 threads started\n");
        std::_Exit(3);
    } catch (const lucent::Error& e) {
        std::fprintf(stderr, "%s\n", e.what());
        std::_Exit(0);
    }
}

TEST(ThreadPool, WhenTheSystemRefusesAThreadTheErrorComesBackWithoutADeadlock) {
#if defined(__SANITIZE_ADDRESS__)
    // AddressSanitizer reserves terabytes of address space for its shadow: under the small
    // RLIMIT_AS this test sets, the child fails in the sanitizer, not in the pool.
    GTEST_SKIP() << "not under AddressSanitizer (scripts/test-sanitized.sh)";
#endif
    EXPECT_EXIT(make_a_pool_too_large_for_memory(), ::testing::ExitedWithCode(0),
                "cannot start thread [0-9]+ of 400");
}

}  // namespace

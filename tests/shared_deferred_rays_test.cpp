// How the CPU backend's workers share their deferred rays (cpu/deferred_rays.h,
// SharedDeferredRays): every published ray is taken exactly once, a worker's own queues
// first; runs are long while many rays are to come and short at the end; a queue is
// reclaimed only when nobody traces a run of it; and workers publishing and taking at once
// lose no ray and take none twice.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "cpu/deferred_rays.h"

namespace {

using lucent::cpu::DeferredOcclusion;
using lucent::cpu::DeferredQueue;
using lucent::cpu::DeferredTrace;
using lucent::cpu::SharedDeferredRays;

/// A queue of `traces` deferred traces and `occlusions` deferred occlusions, each ray's
/// tmin its number (traces first).
DeferredQueue numbered_queue(size_t traces, size_t occlusions, size_t first = 0) {
    DeferredQueue queue;
    for (size_t i = 0; i < traces; ++i) queue.add_trace().ray.tmin = float(first + i);
    for (size_t i = 0; i < occlusions; ++i)
        queue.add_occlusion().ray.tmin = float(first + traces + i);
    return queue;
}

/// Takes every run left for `worker`, counting each ray's takes in `taken` (by number) and
/// the runs' lengths in `lengths`.
void take_all(SharedDeferredRays& shared, unsigned worker, std::vector<int>& taken,
              std::vector<size_t>* lengths = nullptr) {
    SharedDeferredRays::Run run;
    while (shared.take(worker, run)) {
        EXPECT_TRUE(run.traces.empty() || run.occlusions.empty()) << "a run is of one kind";
        for (const DeferredTrace& t : run.traces) ++taken[size_t(t.ray.tmin)];
        for (const DeferredOcclusion& o : run.occlusions) ++taken[size_t(o.ray.tmin)];
        if (lengths) lengths->push_back(run.traces.size() + run.occlusions.size());
        shared.done(run);
    }
}

TEST(SharedDeferredRays, EveryPublishedRayIsTakenOnce) {
    SharedDeferredRays shared(2, 1);
    const DeferredQueue a = numbered_queue(70000, 30000), b = numbered_queue(5000, 0, 100000);
    shared.publish(SharedDeferredRays::queue_id(0, 0), a);
    shared.publish(SharedDeferredRays::queue_id(1, 1), b);
    EXPECT_TRUE(shared.any_left());
    std::vector<int> taken(105000, 0);
    take_all(shared, 0, taken);
    EXPECT_FALSE(shared.any_left());
    for (size_t i = 0; i < taken.size(); ++i) ASSERT_EQ(taken[i], 1) << "ray " << i;
}

TEST(SharedDeferredRays, AWorkersOwnQueuesComeFirst) {
    SharedDeferredRays shared(3, 1);
    const DeferredQueue others = numbered_queue(50000, 0), own = numbered_queue(2000, 0, 50000);
    shared.publish(SharedDeferredRays::queue_id(0, 0), others);
    shared.publish(SharedDeferredRays::queue_id(2, 1), own);
    SharedDeferredRays::Run run;
    ASSERT_TRUE(shared.take(2, run));
    EXPECT_EQ(run.queue, SharedDeferredRays::queue_id(2, 1));
    ASSERT_FALSE(run.traces.empty());
    EXPECT_EQ(run.traces.front().ray.tmin, 50000.0f);
    shared.done(run);
    // Its own all taken, the largest queue left is another's.
    while (run.queue == SharedDeferredRays::queue_id(2, 1)) {
        ASSERT_TRUE(shared.take(2, run));
        shared.done(run);
    }
    EXPECT_EQ(run.queue, SharedDeferredRays::queue_id(0, 0));
}

TEST(SharedDeferredRays, RunsAreLongWhileRaysAreToComeAndShortAtTheEnd) {
    // Four workers, 100 tiles; one has run 10 tiles and published a full queue: at that rate
    // the other 90 tiles bring 590K rays more, so the queue goes in one run.
    constexpr unsigned kWorkers = 4;
    SharedDeferredRays shared(kWorkers, 100);
    for (int i = 0; i < 10; ++i) shared.tile_done(0, 6553 * (i + 1));
    const DeferredQueue full = numbered_queue(65536, 0);
    shared.publish(SharedDeferredRays::queue_id(0, 0), full);
    SharedDeferredRays::Run run;
    ASSERT_TRUE(shared.take(0, run));
    EXPECT_EQ(run.traces.size(), 65536u);
    shared.done(run);

    // At the end (every tile run, nothing queued) the runs shrink with the rays left: each
    // an eighth of them (2 x 4 workers), none under 1,024 rays unless the queue ends.
    for (unsigned w = 0; w < kWorkers; ++w)
        for (int i = 0; i < (w == 0 ? 15 : 25); ++i) shared.tile_done(w, 0);
    const DeferredQueue last = numbered_queue(40000, 0);
    shared.publish(SharedDeferredRays::queue_id(1, 0), last);
    std::vector<int> taken(40000, 0);
    std::vector<size_t> lengths;
    take_all(shared, 1, taken, &lengths);
    ASSERT_GE(lengths.size(), 10u);
    EXPECT_EQ(lengths.front(), 40000u / 8);
    for (size_t i = 1; i < lengths.size(); ++i) {
        EXPECT_LE(lengths[i], lengths[i - 1]) << "run " << i;
        if (i + 1 < lengths.size()) {
            EXPECT_GE(lengths[i], 1024u) << "run " << i;
        }
    }
}

TEST(SharedDeferredRays, AQueueIsReclaimedWhenNoRunOfItIsTraced) {
    SharedDeferredRays shared(2, 1);
    const DeferredQueue queue = numbered_queue(3000, 0);
    const unsigned id = SharedDeferredRays::queue_id(0, 0);
    shared.publish(id, queue);
    SharedDeferredRays::Run run;
    ASSERT_TRUE(shared.take(1, run));  // another worker traces a run of it
    std::atomic<bool> run_done{false}, done_when_reclaimed{false};
    std::thread owner([&] {
        shared.reclaim(id);
        done_when_reclaimed = run_done.load();
    });
    // The owner is given time to return early, if reclaim() were to; whether it did is read
    // from what it saw, not from the time.
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    run_done = true;
    shared.done(run);
    owner.join();
    EXPECT_TRUE(done_when_reclaimed) << "reclaimed while a run of it was traced";
    // What nobody took (a failed launch stops taking) is withdrawn with it.
    EXPECT_FALSE(shared.any_left());
}

TEST(SharedDeferredRays, WorkersPublishingAndTakingAtOnceTakeEachRayOnce) {
    constexpr unsigned kWorkers = 8, kQueuesEach = 6;
    constexpr size_t kRays = 20000;  // a queue's
    SharedDeferredRays shared(kWorkers, kWorkers * kQueuesEach);
    std::vector<std::vector<DeferredQueue>> queues(kWorkers);
    for (unsigned w = 0; w < kWorkers; ++w)
        for (unsigned q = 0; q < kQueuesEach; ++q)
            queues[w].push_back(
                numbered_queue(kRays / 2, kRays / 2, (w * kQueuesEach + q) * kRays));
    std::vector<std::atomic<int>> taken(kWorkers * kQueuesEach * kRays);
    std::vector<std::thread> threads;
    for (unsigned w = 0; w < kWorkers; ++w)
        threads.emplace_back([&, w] {
            auto take_runs = [&] {
                SharedDeferredRays::Run run;
                while (shared.take(w, run)) {
                    for (const DeferredTrace& t : run.traces) ++taken[size_t(t.ray.tmin)];
                    for (const DeferredOcclusion& o : run.occlusions) ++taken[size_t(o.ray.tmin)];
                    shared.done(run);
                }
            };
            // As the backend does: each queue published in turn into one of two slots,
            // whose earlier queue is reclaimed first.
            for (unsigned q = 0; q < kQueuesEach; ++q) {
                const unsigned id = SharedDeferredRays::queue_id(w, q % 2);
                shared.reclaim(id);
                shared.publish(id, queues[w][q]);
                take_runs();
                shared.tile_done(w, 0);
            }
            shared.end_tiles();
            for (;;) {
                const uint32_t seen = shared.news();
                take_runs();
                if (!shared.tiles_running()) break;
                shared.wait_for_news(seen);
            }
        });
    for (auto& t : threads) t.join();
    EXPECT_FALSE(shared.any_left());
    for (size_t i = 0; i < taken.size(); ++i) ASSERT_EQ(taken[i].load(), 1) << "ray " << i;
}

}  // namespace

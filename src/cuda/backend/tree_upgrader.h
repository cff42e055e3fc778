// Upgrades of Builder::kAuto's GPU-built triangle trees (ContextOptions::tree_upgrades): the
// host's binned-SAH tree with spatial splits (Stich et al. 2009), Builder::kBinnedSah's, built
// on a thread of its own from the GPU tree's triangles, to take the GPU tree's place at a
// later launch. The GPU build gives the first launch its tree in about a millisecond; the
// host's traces up to 1.3x faster on Sponza but takes tens of milliseconds (docs/performance.md).
#pragma once

#include <cuda.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cuda/accel/gpu_triangle_bvh.h"

namespace lucent::cuda {

class TreeUpgrader {
  public:
    /// Its thread reads the GPU trees' triangles back with `context` current.
    explicit TreeUpgrader(CUcontext context) : m_context(context) {}
    /// Waits for the build under way; drops the queued ones.
    ~TreeUpgrader();
    TreeUpgrader(const TreeUpgrader&) = delete;
    TreeUpgrader& operator=(const TreeUpgrader&) = delete;

    /// Queues the upgrade of `tree`, `group`'s GPU-built tree as of `version`. Call it with
    /// the context current, after the build was queued on the legacy stream: the triangles
    /// are copied on the device now, behind the build, so the group may rebuild `tree` at
    /// once. A job of the same group not yet started is dropped.
    void submit(const void* group, uint64_t version, const GpuTriangleBvhDevice& tree,
                const GpuBvhBuildOptions& options);

    struct Finished {
        const void* group = nullptr;
        uint64_t version = 0;
        GpuTriangleBvh tree;  // no nodes when the build failed
        std::string error;    // why it failed
        double ready_ms = 0;  // from submit() to the build's end
    };
    /// The builds finished since the last call, oldest first.
    std::vector<Finished> take_finished();
    /// Blocks until no job is queued or under way.
    void wait_idle();

  private:
    struct Job {
        const void* group = nullptr;
        uint64_t version = 0;
        DeviceBuffer triangles, ids;  // copies of the GPU tree's, in leaf order
        size_t count = 0;             // triangles
        GpuBvhBuildOptions options;
        std::chrono::steady_clock::time_point submitted;
    };
    void run();
    static Finished build(Job& job);

    CUcontext m_context;
    std::mutex m_mutex;
    std::condition_variable m_wake, m_idle;
    std::deque<Job> m_queue;
    std::vector<Finished> m_finished;
    bool m_busy = false, m_stop = false;
    std::thread m_thread;  // started by the first submit
};

}  // namespace lucent::cuda

#include "bench/rays/stream_passes.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

namespace lucent::bench {

std::vector<accel::StreamRay> stream_rays(const RaySet& set) {
    std::vector<accel::StreamRay> rays(set.size());
    for (size_t i = 0; i < set.size(); ++i)
        rays[i] = accel::StreamRay{set.origin[i], 0.0f, set.direction[i], set.tmax[i]};
    return rays;
}

StreamPasses::StreamPasses(const accel::TriangleAccel& accel, unsigned threads)
    : m_accel(accel), m_threads(std::max(threads, 1u)), m_workspaces(m_threads) {}

template <class Trace>
double StreamPasses::run(size_t count, const Trace& trace) {
    // Two batches a thread at least, so that the threads finish together, and no more than
    // a stream query takes at once (accel::kStreamBatch).
    const size_t per_thread = (count + 2 * m_threads - 1) / (2 * m_threads);
    const size_t batch = std::clamp<size_t>(per_thread, 4096, accel::kStreamBatch);
    struct alignas(64) Counter {
        std::atomic<size_t> next{0};
    };
    Counter counter;
    auto worker = [&counter, &trace, count, batch](accel::RayStreamWorkspace& workspace) {
        for (;;) {
            const size_t begin = counter.next.fetch_add(batch, std::memory_order_relaxed);
            if (begin >= count) return;
            trace(begin, std::min(count, begin + batch) - begin, workspace);
        }
    };
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> pool;
    for (unsigned k = 0; k < m_threads; ++k) pool.emplace_back(worker, std::ref(m_workspaces[k]));
    for (std::thread& t : pool) t.join();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double StreamPasses::closest(std::span<const accel::StreamRay> rays,
                             std::span<accel::StreamHit> hits) {
    return run(rays.size(), [&](size_t begin, size_t n, accel::RayStreamWorkspace& workspace) {
        m_accel.intersect_stream(rays.subspan(begin, n), hits.subspan(begin, n), workspace);
    });
}

double StreamPasses::occluded(std::span<const accel::StreamRay> rays,
                              std::span<uint8_t> blocked) {
    return run(rays.size(), [&](size_t begin, size_t n, accel::RayStreamWorkspace& workspace) {
        m_accel.occluded_stream(rays.subspan(begin, n), blocked.subspan(begin, n), workspace);
    });
}

}  // namespace lucent::bench

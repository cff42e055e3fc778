// The CPU backend: the launch grid cut into tiles, taken by the workers of a thread pool
// in guided runs; each launch index runs the ray-generation program, and an exception
// raised anywhere below it ends that index and runs the exception program. The rays the
// programs defer wait in their worker's queue and are traced together (deferred_rays.h):
// a worker publishes its queue when it is full and when its tiles are done, and all the
// workers trace the published rays, in runs, between their tiles and after them.
#include <algorithm>
#include <atomic>
#include <exception>
#include <map>
#include <memory>
#include <mutex>

#include "core/backend.h"
#include "cpu/cpu_state.h"
#include "cpu/deferred_rays.h"
#include "cpu/launch_index.h"
#include "cpu/thread_pool.h"

namespace lucent::cpu {

namespace {

constexpr unsigned kTileWidth = 8, kTileHeight = 8, kTile1D = 64;

/// The tiles of a piece handed out in runs of consecutive tiles, each run a share of the
/// tiles still left (OpenMP's guided schedule). A worker's deferred rays then come from a
/// few compact parts of the grid, so that their ray streams share the tree's nodes, where
/// tiles handed out one at a time scatter each worker's rays over the whole grid; and the
/// last runs are single tiles, so that the workers still finish together.
class GuidedTiles {
  public:
    GuidedTiles(uint64_t count, unsigned workers)
        : m_count(count), m_share(2 * uint64_t(std::max(workers, 1u))) {}
    /// The next run of tiles, [first, first + n); false when none is left.
    bool take(uint64_t& first, uint64_t& n) {
        uint64_t next = m_next.load(std::memory_order_relaxed);
        do {
            if (next >= m_count) return false;
            n = std::max<uint64_t>(1, (m_count - next) / m_share);
        } while (!m_next.compare_exchange_weak(next, next + n, std::memory_order_relaxed));
        first = next;
        return true;
    }
    /// Hands out nothing more (a worker failed).
    void stop() { m_next = m_count; }

  private:
    std::atomic<uint64_t> m_next{0};
    const uint64_t m_count, m_share;
};

class CpuBackend final : public core::Backend {
  public:
    explicit CpuBackend(unsigned threads) : m_pool(threads) {
        for (unsigned w = 0; w < m_pool.size(); ++w) {
            for (unsigned k = 0; k < SharedDeferredRays::kQueuesPerWorker; ++k)
                m_queues.push_back(std::make_unique<DeferredQueue>());
            m_tracers.push_back(std::make_unique<DeferredTracer>());
        }
    }

    std::string name() const override {
        return "cpu (" + std::to_string(m_pool.size()) + " thread" +
               (m_pool.size() == 1 ? "" : "s") + ")";
    }

    void begin_launch(const core::CompiledScene& scene, const core::LaunchSpec& spec,
                      LaunchReport& /*report*/) override {
        m_scene = &scene;
        m_spec = spec;
        m_exceptions.assign(m_pool.size(), WorkerExceptions{});
    }

    void run_piece(core::LaunchPiece piece) override {
        const uint3 size = m_spec.size;
        // A piece of whole rows (row = z * height + y) in 8x8 tiles, or of one row in 64s.
        const bool by_rows = m_spec.by_rows();
        const uint64_t first_row = by_rows ? piece.first / size.x : 0;
        const uint64_t rows = by_rows ? piece.last / size.x - first_row : 1;
        const uint64_t tiles_x = by_rows ? (size.x + kTileWidth - 1) / kTileWidth
                                         : (piece.last - piece.first + kTile1D - 1) / kTile1D;
        const uint64_t tile_count = tiles_x * ((rows + kTileHeight - 1) / kTileHeight);
        const unsigned workers = unsigned(std::min<uint64_t>(tile_count, m_pool.size()));
        PieceWork work(m_scene->entries[m_spec.entry], piece, tiles_x, first_row, rows, tile_count,
                       workers);
        m_pool.run([&](unsigned worker) { run_worker(worker, work); },
                   workers);  // no more workers than tiles
        // Every published ray is traced (or the launch has failed, and its rays are not).
        for (auto& queue : m_queues) queue->clear();
        if (work.error) std::rethrow_exception(work.error);
    }

    void end_launch(LaunchReport& report) override {
        for (auto& w : m_exceptions)
            for (auto& [code, entry] : w.by_code) {
                auto& m = m_merged[code];
                m.count += entry.count;
                if (entry.first_linear < m.first_linear) {
                    m.first_linear = entry.first_linear;
                    m.first_index = entry.first_index;
                }
            }
        for (auto& [code, m] : m_merged) report.exceptions[code] = {m.count, m.first_index};
        m_merged.clear();
        m_exceptions.clear();
    }

    bool uses_host_storage() const override { return true; }

  private:
    /// What the workers of one piece share.
    struct PieceWork {
        PieceWork(const core::CompiledEntry& entry, core::LaunchPiece piece, uint64_t tiles_x,
                  uint64_t first_row, uint64_t rows, uint64_t tile_count, unsigned workers)
            : entry(entry),
              piece(piece),
              tiles_x(tiles_x),
              first_row(first_row),
              rows(rows),
              tiles(tile_count, workers),
              rays(workers, tile_count) {}
        const core::CompiledEntry& entry;
        const core::LaunchPiece piece;
        const uint64_t tiles_x, first_row, rows;
        GuidedTiles tiles;
        SharedDeferredRays rays;  // the rays the programs deferred
        std::mutex error_mutex;
        std::exception_ptr error;  // the first that is not a program's exception
        std::atomic<bool> failed{false};
        /// Keeps the exception being handled, if it is the first, and stops the others early.
        void fail() {
            std::lock_guard lock(error_mutex);
            if (!error) error = std::current_exception();
            tiles.stop();
            failed = true;
        }
    };

    /// What worker `worker` does in a piece: it runs tiles, publishing its queue of deferred
    /// rays when it is full (and deferring to its other queue) and taking runs of the
    /// published rays between tiles; then it publishes what it still holds and takes runs
    /// until every worker's tiles are done and no ray is left (SharedDeferredRays).
    void run_worker(unsigned worker, PieceWork& work) {
        const core::CompiledEntry& e = work.entry;
        SharedDeferredRays& shared = work.rays;
        ThreadState ts;
        ts.scene = m_scene;
        ts.launch_size = m_spec.size;
        ts.device_keys = m_spec.device_keys.data();
        ts.device_slots = unsigned(m_spec.device_keys.size());
        unsigned k = 0;  // the queue the programs defer to: the worker's k-th
        auto queue_id = [&] { return SharedDeferredRays::queue_id(worker, k); };
        ts.deferred = m_queues[queue_id()].get();
        ts.programs_stack_top = static_cast<const char*>(__builtin_frame_address(0));
        DeferredTracer& tracer = *m_tracers[worker];
        WorkerExceptions& exceptions = m_exceptions[worker];
        // Takes runs of the published rays and traces them, until none is left. (A C++
        // exception that is not the engine's, e.g. std::bad_alloc in a program or the
        // lucent::Error of a misused call, fails the launch.)
        auto trace_runs = [&] {
            SharedDeferredRays::Run run;
            while (!work.failed && shared.take(worker, run)) {
                struct Done {  // traced, or failed: its queue may change again
                    SharedDeferredRays& shared;
                    const SharedDeferredRays::Run& run;
                    ~Done() { shared.done(run); }
                } done{shared, run};
                tracer.trace(ts, e, exceptions, run.traces);
                tracer.occlude(ts, e, exceptions, run.occlusions);
            }
        };
        auto publish_full_queue = [&] {
            if (!ts.deferred->full()) return;
            shared.publish(queue_id(), *ts.deferred);
            trace_runs();
            k = (k + 1) % SharedDeferredRays::kQueuesPerWorker;
            shared.reclaim(queue_id());  // others may still trace runs of it
            ts.deferred = m_queues[queue_id()].get();
            ts.deferred->clear();
        };
        set_thread_state(&ts);
        try {
            for (uint64_t first, n; work.tiles.take(first, n);)
                for (uint64_t tile = first; tile < first + n; ++tile) {
                    run_tile(ts, e, tile, work, exceptions, publish_full_queue);
                    shared.tile_done(worker, ts.deferred->size());
                    if (shared.any_left()) trace_runs();  // another's full queue
                }
            shared.publish(queue_id(), *ts.deferred);
        } catch (...) {
            work.fail();
        }
        shared.end_tiles();
        // The rays still queued, and those the workers that still run tiles publish, so that
        // none is left alone with its own.
        try {
            for (;;) {
                const uint32_t seen = shared.news();
                trace_runs();
                if (work.failed || !shared.tiles_running()) break;  // none comes after
                shared.wait_for_news(seen);
            }
        } catch (...) {
            work.fail();
        }
        set_thread_state(nullptr);
    }

    /// Runs the launch indices of tile `tile` of a piece (8x8 of whole rows, or 64 of one
    /// row), calling after_index() after each.
    template <class AfterIndex>
    void run_tile(ThreadState& ts, const core::CompiledEntry& e, uint64_t tile,
                  const PieceWork& work, WorkerExceptions& exceptions,
                  AfterIndex&& after_index) const {
        const uint3 size = m_spec.size;
        const core::LaunchPiece piece = work.piece;
        const uint64_t tx = tile % work.tiles_x, ty = tile / work.tiles_x;
        if (!m_spec.by_rows()) {
            const uint64_t i0 = piece.first + tx * kTile1D;
            const uint64_t i1 = std::min(piece.last, i0 + kTile1D);
            for (uint64_t i = i0; i < i1; ++i) {
                run_index(ts, e, uint3{unsigned(i), 0, 0}, exceptions);
                after_index();
            }
            return;
        }
        const unsigned x0 = unsigned(tx) * kTileWidth;
        const unsigned x1 = std::min(size.x, x0 + kTileWidth);
        const uint64_t r0 = work.first_row + ty * kTileHeight;
        const uint64_t r1 = std::min(work.first_row + work.rows, r0 + kTileHeight);
        for (uint64_t r = r0; r < r1; ++r) {
            const unsigned y = unsigned(r % size.y), z = unsigned(r / size.y);
            for (unsigned x = x0; x < x1; ++x) {
                run_index(ts, e, uint3{x, y, z}, exceptions);
                after_index();
            }
        }
    }

    static void run_index(ThreadState& ts, const core::CompiledEntry& e, uint3 index,
                          WorkerExceptions& out) {
        enter_index(ts, index);
        try {
            e.ray_generation.entry<RayGenerationFn>()(e.ray_generation.rec());
        } catch (const ProgramException& ex) {
            handle_program_exception(ts, e, index, ex, out);
        }
    }

    ThreadPool m_pool;
    const core::CompiledScene* m_scene = nullptr;
    core::LaunchSpec m_spec;
    std::vector<WorkerExceptions> m_exceptions;  // per worker, for the launch's pieces
    std::map<int, WorkerExceptions::Entry> m_merged;
    // Per worker, kept from launch to launch: its deferred rays, and the memory it traces
    // them in.
    std::vector<std::unique_ptr<DeferredQueue>> m_queues;
    std::vector<std::unique_ptr<DeferredTracer>> m_tracers;
};

}  // namespace
}  // namespace lucent::cpu

namespace lucent::core {
std::unique_ptr<Backend> make_cpu_backend(unsigned threads) {
    return std::make_unique<cpu::CpuBackend>(threads);
}
}  // namespace lucent::core

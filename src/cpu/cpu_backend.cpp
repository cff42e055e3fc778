// The CPU backend: the launch grid cut into tiles, taken by the workers of a thread pool
// from a shared counter; each launch index runs the ray-generation program, and an
// exception raised anywhere below it ends that index and runs the exception program.
#include <algorithm>
#include <atomic>
#include <exception>
#include <map>
#include <mutex>

#include "core/backend.h"
#include "cpu/cpu_state.h"
#include "cpu/thread_pool.h"

namespace lucent::cpu {

namespace {

constexpr unsigned kTileWidth = 8, kTileHeight = 8, kTile1D = 64;

struct WorkerExceptions {
    struct Entry {
        uint64_t count = 0;
        uint64_t first_linear = ~0ull;
        uint3 first_index{0, 0, 0};
    };
    std::map<int, Entry> by_code;
    void add(int code, uint3 index, uint64_t linear) {
        Entry& e = by_code[code];
        ++e.count;
        if (linear < e.first_linear) {
            e.first_linear = linear;
            e.first_index = index;
        }
    }
};

class CpuBackend final : public core::Backend {
  public:
    explicit CpuBackend(unsigned threads) : m_pool(threads) {}

    std::string name() const override {
        return "cpu (" + std::to_string(m_pool.size()) + " thread" +
               (m_pool.size() == 1 ? "" : "s") + ")";
    }

    void launch(const core::CompiledScene& scene, unsigned entry, uint3 size,
                LaunchReport& report) override {
        const core::CompiledEntry& e = scene.entries[entry];
        const bool one_d = size.y == 1 && size.z == 1;
        const unsigned tiles_x =
            one_d ? (size.x + kTile1D - 1) / kTile1D : (size.x + kTileWidth - 1) / kTileWidth;
        const unsigned tiles_y = one_d ? 1 : (size.y + kTileHeight - 1) / kTileHeight;
        const uint64_t tile_count = uint64_t(tiles_x) * tiles_y * size.z;

        std::atomic<uint64_t> next_tile{0};
        std::vector<WorkerExceptions> exceptions(m_pool.size());
        std::mutex error_mutex;
        std::exception_ptr error;

        m_pool.run([&](unsigned worker) {
            ThreadState ts;
            ts.scene = &scene;
            ts.launch_size = size;
            ts.frames.resize(scene.max_depth);
            set_thread_state(&ts);
            try {
                for (uint64_t tile; (tile = next_tile.fetch_add(1)) < tile_count;) {
                    unsigned z = unsigned(tile / (uint64_t(tiles_x) * tiles_y));
                    unsigned rest = unsigned(tile % (uint64_t(tiles_x) * tiles_y));
                    unsigned tx = rest % tiles_x, ty = rest / tiles_x;
                    unsigned x0 = tx * (one_d ? kTile1D : kTileWidth), y0 = ty * kTileHeight;
                    unsigned x1 = std::min(size.x, x0 + (one_d ? kTile1D : kTileWidth));
                    unsigned y1 = one_d ? 1 : std::min(size.y, y0 + kTileHeight);
                    for (unsigned y = y0; y < y1; ++y)
                        for (unsigned x = x0; x < x1; ++x)
                            run_index(ts, scene, e, uint3{x, y, z}, exceptions[worker]);
                }
            } catch (...) {
                // A C++ exception that is not the engine's (e.g. std::bad_alloc in a program).
                std::lock_guard lock(error_mutex);
                if (!error) error = std::current_exception();
                next_tile = tile_count;  // stop the others early
            }
            set_thread_state(nullptr);
        });
        if (error) std::rethrow_exception(error);

        std::map<int, WorkerExceptions::Entry> merged;
        for (auto& w : exceptions)
            for (auto& [code, entry] : w.by_code) {
                auto& m = merged[code];
                m.count += entry.count;
                if (entry.first_linear < m.first_linear) {
                    m.first_linear = entry.first_linear;
                    m.first_index = entry.first_index;
                }
            }
        for (auto& [code, m] : merged) report.exceptions[code] = {m.count, m.first_index};
    }

  private:
    static void run_index(ThreadState& ts, const core::CompiledScene& scene,
                          const core::CompiledEntry& e, uint3 index, WorkerExceptions& out) {
        ts.launch_index = index;
        ts.depth = 0;
        ts.context = ProgramContext::kRayGeneration;
        ts.print_here = scene.print_enabled &&
                        (scene.print_index.x < 0 || unsigned(scene.print_index.x) == index.x) &&
                        (scene.print_index.y < 0 || unsigned(scene.print_index.y) == index.y) &&
                        (scene.print_index.z < 0 || unsigned(scene.print_index.z) == index.z);
        try {
            e.ray_generation.entry<RayGenerationFn>()(e.ray_generation.rec());
        } catch (const ProgramException& ex) {
            uint64_t linear =
                (uint64_t(index.z) * ts.launch_size.y + index.y) * ts.launch_size.x + index.x;
            out.add(ex.code, index, linear);
            if (e.exception && scene.exception_enabled(ex.code)) {
                ts.depth = 0;
                ts.context = ProgramContext::kException;
                try {
                    e.exception.entry<ExceptionFn>()(e.exception.rec(),
                                                     ExceptionInfo{ex.code, index, ex.detail});
                } catch (const ProgramException& nested) {
                    // An exception program that raises is counted, not re-run.
                    out.add(nested.code, index, linear);
                }
            }
        }
    }

    ThreadPool m_pool;
};

}  // namespace
}  // namespace lucent::cpu

namespace lucent::core {
std::unique_ptr<Backend> make_cpu_backend(unsigned threads) {
    return std::make_unique<cpu::CpuBackend>(threads);
}
}  // namespace lucent::core

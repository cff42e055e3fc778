// One launch spread over several devices (OptiX's multi-GPU launch, paper §5): every device
// holds the whole scene and every buffer; the launch's rows are taken piece by piece from a
// shared queue (core/piece_queue.h); then each device's copy of the buffers the launch may
// have written receives the pieces the other devices ran, so all copies, and the images, are
// those of a one-device run. docs/multi-device.md says what a program may write.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <mutex>
#include <set>

#include "core/backend.h"
#include "core/launch_buffers.h"
#include "core/piece_queue.h"
#include "lucent/error.h"

namespace lucent::core {

namespace {

using Clock = std::chrono::steady_clock;
double ms_between(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

/// Per entry point and launch size: is spreading the launch worth its exchange? A small
/// launch (IGI's passes at 1/4 resolution) can run faster whole on one device. Launch 1
/// is spread (and warms up), launch 2 runs whole, launch 3 is spread; from then on, the
/// faster of launches 2 and 3, each timed with its exchange.
struct SplitChoice {
    unsigned launches = 0;
    double ms[2] = {0, 0};  // [whole, spread]
    int choice = -1;
    bool next_spread() const { return choice >= 0 ? choice == 1 : launches != 1; }
    void record(bool spread, double launch_ms) {
        if (choice >= 0) return;
        if (launches >= 1) ms[spread] = launch_ms;
        if (++launches == 3) choice = ms[1] < ms[0] ? 1 : 0;
    }
};

class MultiDeviceBackend final : public Backend {
  public:
    MultiDeviceBackend(std::vector<std::unique_ptr<Backend>> devices,
                       std::vector<std::string> names, unsigned piece_rows,
                       RunOnWorkers run_on_workers)
        : m_devices(std::move(devices)),
          m_names(std::move(names)),
          m_piece_rows(piece_rows),
          m_run_on_workers(std::move(run_on_workers)) {
        for (auto& a : m_devices)
            for (auto& b : m_devices)
                if (a != b) a->connect(*b);
        std::vector<Backend*> all;
        for (auto& d : m_devices) all.push_back(d.get());
        if (all.size() > 1 && !std::getenv("LUCENT_NO_SHARED_TILE_QUEUE"))
            m_tile_queue = m_devices[0]->share_tile_queue(all);
    }

    std::string name() const override {
        std::string s = std::to_string(m_devices.size()) + " device" +
                        (m_devices.size() == 1 ? "" : "s") + ": ";
        for (size_t d = 0; d < m_devices.size(); ++d)
            s += (d ? " + " : "") + m_devices[d]->name();
        return s;
    }

    bool traces_on_host() const override {
        for (const auto& d : m_devices)
            if (d->traces_on_host()) return true;
        return false;
    }

    void launch(const CompiledScene& scene, const LaunchSpec& spec, LaunchReport& report) override {
        const unsigned n = unsigned(m_devices.size());
        // What a new compile drops from the devices must reach the host first.
        if (&scene != m_scene || scene.generation != m_generation) {
            // A new compile may drop an owner's copy: the host's becomes the one to catch
            // up from.
            flush_host_copies();
            for (auto& [raw, s] : m_behind) s.owner = kHostCopy;
        }
        m_scene = &scene;
        m_generation = scene.generation;

        // Pieces of launch-shaped buffers are exchanged; any other written buffer can be
        // written anywhere by any index, so such a launch runs whole on one device.
        std::vector<std::shared_ptr<const Buffer>> shaped, other;
        for (auto& b : launch_buffers(scene, spec.entry, &CompiledProgram::writable_buffers))
            (launch_shaped(*b, spec.size) ? shaped : other).push_back(b);
        std::vector<double>& speeds = m_speeds[{spec.entry, spec.count()}];
        speeds.resize(n, 0.0);
        PieceQueue queue(spec, speeds, m_piece_rows);
        const bool can_split =
            n > 1 && other.empty() && queue.units() >= 2 * n * queue.min_units();
        // Fixed pieces (tests) always spread; else measured (SplitChoice).
        SplitChoice& choice = m_split_choice[{spec.entry, spec.count()}];
        const bool split = can_split && (m_piece_rows > 0 || choice.next_spread());
        const unsigned whole_on = fastest(speeds);
        const auto viewed = launch_buffers(scene, spec.entry, &CompiledProgram::buffers);
        if (spec.next_piece) {  // pieces from the ranks' counter: every device takes them
            if (!other.empty())
                throw Error(
                    "multi-device backend: pieces given for a launch that writes "
                    "buffers of another shape than the launch");
            run_in_pieces(scene, spec, shaped, other, viewed, nullptr, whole_on, speeds, report);
            return;
        }
        const auto t0 = Clock::now();
        if (split && m_tile_queue)
            run_with_shared_tiles(scene, spec, shaped, viewed, report);
        else
            run_in_pieces(scene, spec, shaped, other, viewed, split ? &queue : nullptr, whole_on,
                          speeds, report);
        if (can_split && m_piece_rows == 0) choice.record(split, ms_between(t0, Clock::now()));
    }

    std::shared_ptr<DisplayFrame> display_frame(const Buffer& output) override {
        if (m_devices.size() == 1) return m_devices[0]->display_frame(output);
        return Backend::display_frame(output);  // gathered on the host
    }

    std::vector<std::shared_ptr<const Buffer>> host_copies_behind() const override {
        std::vector<std::shared_ptr<const Buffer>> behind;
        for (const auto& [raw, buffer] : m_host_stale) behind.push_back(buffer);
        for (const auto& device : m_devices)  // one device: it marked its outputs itself
            for (auto& buffer : device->host_copies_behind()) behind.push_back(std::move(buffer));
        return behind;
    }

    void fetch(const Buffer& buffer) override {
        if (m_devices.size() == 1) return m_devices[0]->fetch(buffer);
        auto stale = m_behind.find(&buffer);
        if (stale != m_behind.end() && stale->second.version == buffer.version()) {
            if (stale->second.owner != kHostCopy)  // else the host copy is current
                m_devices[unsigned(stale->second.owner)]->download_range(
                    buffer, 0, buffer.count() * buffer.element().size);
            return;
        }
        // Every device's copy is complete after a spread launch: any non-host one will do.
        for (auto& device : m_devices)
            if (!device->uses_host_storage()) {
                device->download_range(buffer, 0, buffer.count() * buffer.element().size);
                return;
            }
    }

    // A multi-device backend is not itself one of a set of devices.
    void begin_launch(const CompiledScene&, const LaunchSpec&, LaunchReport&) override {
        throw Error("multi-device backend: launches whole, not in pieces");
    }
    void run_piece(LaunchPiece) override {}
    void end_launch(LaunchReport&) override {}

  private:
    /// Devices take pieces from `queue` (or, without one, device `whole_on` runs the whole
    /// launch); then every device's copy receives the pieces the others ran.
    void run_in_pieces(const CompiledScene& scene, const LaunchSpec& spec,
                       const std::vector<std::shared_ptr<const Buffer>>& shaped,
                       const std::vector<std::shared_ptr<const Buffer>>& other,
                       const std::vector<std::shared_ptr<const Buffer>>& viewed, PieceQueue* queue,
                       unsigned whole_on, std::vector<double>& speeds, LaunchReport& report) {
        const unsigned n = unsigned(m_devices.size());
        const bool external = bool(spec.next_piece);  // pieces from the ranks' counter
        const bool split = queue != nullptr || external;
        std::vector<LaunchReport> reports(n);
        std::vector<std::vector<LaunchPiece>> pieces(n);
        std::vector<double> busy(n, 0.0);
        // The devices that run: every one, or only `whole_on` (the others catch up when
        // they next run).
        auto runs = [&](unsigned d) { return split || d == whole_on; };
        run_on_devices([&](unsigned d) {
            if (runs(d)) m_devices[d]->begin_launch(scene, spec, reports[d]);
        });
        for (unsigned d = 0; d < n; ++d)
            if (runs(d)) catch_up(d, viewed);
        run_on_devices([&](unsigned d) {
            if (!runs(d)) return;
            const auto t0 = Clock::now();
            if (split) {
                while (auto piece = external ? spec.next_piece() : queue->take(d)) {
                    m_devices[d]->run_piece(*piece);
                    pieces[d].push_back(*piece);
                }
            } else if (d == whole_on) {
                LaunchPiece all{0, spec.count()};
                m_devices[d]->run_piece(all);
                pieces[d].push_back(all);
            }
            m_devices[d]->end_launch(reports[d]);
            busy[d] = ms_between(t0, Clock::now());
        });

        const auto t_exchange = Clock::now();
        if (split)
            exchange(shaped, pieces);
        else
            mark_behind(whole_on, shaped, other);
        report.exchange_ms = ms_between(t_exchange, Clock::now());
        merge_reports(reports, pieces, busy, spec, report);
        trace(spec, split ? "pieces" : "whole", report);
        if (split && !external) {
            // Each device's speed on this entry and size, for the next launch's pieces.
            for (unsigned d = 0; d < n; ++d) {
                const double indices = double(report.devices[d].indices);
                if (indices > 0 && busy[d] > 0) {
                    const double speed = indices / busy[d];
                    speeds[d] = speeds[d] > 0 ? 0.5 * (speeds[d] + speed) : speed;
                }
            }
        }
    }

    /// GPUs sharing one tile counter: each runs the whole launch, taking tiles as the
    /// threads of one GPU do; then each gathers the tiles the others ran.
    void run_with_shared_tiles(const CompiledScene& scene, const LaunchSpec& spec,
                               const std::vector<std::shared_ptr<const Buffer>>& shaped,
                               const std::vector<std::shared_ptr<const Buffer>>& viewed,
                               LaunchReport& report) {
        const unsigned n = unsigned(m_devices.size());
        std::vector<LaunchReport> reports(n);
        std::vector<double> busy(n, 0.0);
        const auto t_begin = Clock::now();
        run_on_devices([&](unsigned d) { m_devices[d]->begin_launch(scene, spec, reports[d]); });
        for (unsigned d = 0; d < n; ++d) catch_up(d, viewed);
        const auto t0 = Clock::now();
        m_tile_queue->run(spec);
        run_on_devices([&](unsigned d) {
            m_devices[d]->end_launch(reports[d]);
            busy[d] = ms_between(t0, Clock::now());
        });
        const auto t_exchange = Clock::now();
        std::vector<uint64_t> indices;
        m_tile_queue->gather(spec, shaped, indices);
        report.exchange_ms = ms_between(t_exchange, Clock::now());
        remember_host_stale(shaped, {});
        // The report lists tiles as pieces: each device's share of the 32-index tiles.
        std::vector<std::vector<LaunchPiece>> pieces(n);
        merge_reports(reports, pieces, busy, spec, report);
        for (unsigned d = 0; d < n; ++d) {
            report.devices[d].indices = indices[d];
            report.devices[d].pieces = unsigned((indices[d] + 31) / 32);
        }
        if (m_trace)
            std::fprintf(stderr, "multi-device: shared tiles: begin %.3f ms, run %.3f ms\n",
                         ms_between(t_begin, t0), ms_between(t0, t_exchange));
        trace(spec, "shared tiles", report);
    }

    void trace(const LaunchSpec& spec, const char* how, const LaunchReport& report) const {
        if (!m_trace) return;
        std::fprintf(stderr, "multi-device: entry %u, %llu indices, %s, exchange %.3f ms:",
                     spec.entry, (unsigned long long)spec.count(), how, report.exchange_ms);
        for (const auto& d : report.devices)
            std::fprintf(stderr, " [%s %u pieces %llu indices %.3f ms]", d.device.c_str(),
                         d.pieces, (unsigned long long)d.indices, d.busy_ms);
        std::fprintf(stderr, "\n");
    }

    std::vector<unsigned> all_devices() const {
        std::vector<unsigned> all(m_devices.size());
        for (unsigned d = 0; d < all.size(); ++d) all[d] = d;
        return all;
    }
    bool same_copy(unsigned a, unsigned b) const {
        return a == b || (m_devices[a]->uses_host_storage() && m_devices[b]->uses_host_storage());
    }

    /// A launch ran whole on `owner`: the others' copies of what it wrote are behind; each
    /// catches up only when a launch it runs views the buffer (bring_up_to_date), so
    /// launches that all run whole on one device copy nothing.
    void mark_behind(unsigned owner, const std::vector<std::shared_ptr<const Buffer>>& shaped,
                     const std::vector<std::shared_ptr<const Buffer>>& other) {
        const unsigned n = unsigned(m_devices.size());
        bool host_current = false;
        for (unsigned d = 0; d < n; ++d)
            host_current = host_current || (same_copy(d, owner) && m_devices[d]->uses_host_storage());
        for (const auto* list : {&shaped, &other})
            for (const auto& b : *list) {
                Behind s{b, int(owner), b->version(), std::vector<bool>(n, false)};
                bool any = false;
                for (unsigned d = 0; d < n; ++d) any = any || (s.devices[d] = !same_copy(d, owner));
                if (any) m_behind[b.get()] = std::move(s);
            }
        if (n == 1) m_devices[0]->publish_outputs();
        else if (!host_current) remember_host_stale(shaped, other);
    }

    /// After device d's begin_launch, before it runs: its copies of `buffers` that a whole
    /// launch elsewhere left behind receive the owner's copy (or the host's). New host
    /// contents (a newer version) supersede: every device has uploaded them.
    void catch_up(unsigned d, const std::vector<std::shared_ptr<const Buffer>>& buffers) {
        for (const auto& b : buffers) {
            auto found = m_behind.find(b.get());
            if (found == m_behind.end()) continue;
            Behind& s = found->second;
            if (s.version != b->version()) {
                m_behind.erase(found);
                continue;
            }
            if (!s.devices[d]) continue;
            const size_t bytes = b->count() * b->element().size;
            if (s.owner == kHostCopy) {
                if (!m_devices[d]->uses_host_storage()) m_devices[d]->upload_range(*b, 0, bytes);
            } else {
                m_devices[unsigned(s.owner)]->copy_range_to(*m_devices[d], *b, 0, bytes);
            }
            for (unsigned e = 0; e < s.devices.size(); ++e)
                if (same_copy(e, d)) s.devices[e] = false;
            if (std::none_of(s.devices.begin(), s.devices.end(), [](bool x) { return x; }))
                m_behind.erase(found);
        }
    }

    /// Runs job(d) for every device d at once, one thread each; rethrows the first error.
    template <class Job>
    void run_on_devices(const Job& job) {
        std::mutex mutex;
        std::exception_ptr error;
        m_run_on_workers([&](unsigned d) {
            try {
                job(d);
            } catch (...) {
                std::lock_guard lock(mutex);
                if (!error) error = std::current_exception();
            }
        });
        if (error) std::rethrow_exception(error);
    }

    static unsigned fastest(const std::vector<double>& speeds) {
        return unsigned(std::max_element(speeds.begin(), speeds.end()) - speeds.begin());
    }

    /// After the pieces: every device's copy of each written buffer receives the ranges
    /// other devices wrote. Devices whose copy is host storage (the CPU) share one copy:
    /// the first of them receives for all. Each device receives on its own thread.
    void exchange(const std::vector<std::shared_ptr<const Buffer>>& shaped,
                  const std::vector<std::vector<LaunchPiece>>& pieces) {
        const unsigned n = unsigned(m_devices.size());
        int host_receiver = -1;
        for (unsigned d = 0; d < n && host_receiver < 0; ++d)
            if (m_devices[d]->uses_host_storage()) host_receiver = int(d);
        run_on_devices([&](unsigned d) {
            if (m_devices[d]->uses_host_storage() && int(d) != host_receiver) return;
            for (unsigned owner = 0; owner < n; ++owner) {
                if (same_copy(owner, d)) continue;
                for (const LaunchPiece& piece : pieces[owner])
                    for (const auto& b : shaped) {
                        const size_t element = b->element().size;
                        m_devices[owner]->copy_range_to(*m_devices[d], *b, piece.first * element,
                                                        (piece.last - piece.first) * element);
                    }
            }
        });
        if (host_receiver < 0) remember_host_stale(shaped, {});
    }

    /// No device keeps its copy in host storage: the host copies are fetched when read.
    void remember_host_stale(const std::vector<std::shared_ptr<const Buffer>>& shaped,
                             const std::vector<std::shared_ptr<const Buffer>>& other) {
        for (const auto* list : {&shaped, &other})
            for (const auto& b : *list) {
                b->mark_device_newer();
                m_host_stale[b.get()] = b;
            }
    }

    /// Fetches every buffer whose host copy is behind the devices' (before a new compile
    /// lets the devices drop their copies).
    void flush_host_copies() {
        for (auto& [raw, buffer] : m_host_stale) buffer->sync_from_device();
        m_host_stale.clear();
    }

    void merge_reports(const std::vector<LaunchReport>& reports,
                       const std::vector<std::vector<LaunchPiece>>& pieces,
                       const std::vector<double>& busy, const LaunchSpec& spec,
                       LaunchReport& report) {
        const uint3 size = spec.size;
        auto linear = [&](uint3 i) {
            return (uint64_t(i.z) * size.y + i.y) * size.x + i.x;
        };
        report.jit_cached = true;
        for (unsigned d = 0; d < m_devices.size(); ++d) {
            const LaunchReport& r = reports[d];
            report.jit_ms = std::max(report.jit_ms, r.jit_ms);
            report.jit_cached = report.jit_cached && (r.jit_ms == 0 || r.jit_cached);
            report.kernel_ms = std::max(report.kernel_ms, r.kernel_ms);
            for (const auto& [code, e] : r.exceptions) {
                auto [it, fresh] = report.exceptions.try_emplace(code, e);
                if (fresh) continue;
                it->second.count += e.count;
                if (linear(e.first_index) < linear(it->second.first_index))
                    it->second.first_index = e.first_index;
            }
            LaunchReport::DeviceShare share;
            share.device = m_names[d];
            for (const LaunchPiece& p : pieces[d]) share.indices += p.last - p.first;
            share.pieces = unsigned(pieces[d].size());
            share.busy_ms = busy[d];
            report.devices.push_back(share);
        }
        if (report.jit_ms == 0) report.jit_cached = false;
    }

    std::vector<std::unique_ptr<Backend>> m_devices;
    std::vector<std::string> m_names;
    unsigned m_piece_rows;
    RunOnWorkers m_run_on_workers;  // a worker per device
    const CompiledScene* m_scene = nullptr;
    uint64_t m_generation = 0;
    std::map<std::pair<unsigned, uint64_t>, std::vector<double>> m_speeds;  // by entry, count
    std::map<std::pair<unsigned, uint64_t>, SplitChoice> m_split_choice;    // by entry, count
    std::map<const Buffer*, std::shared_ptr<const Buffer>> m_host_stale;
    std::unique_ptr<SharedTileQueue> m_tile_queue;  // GPUs with peer atomics; else null
    static constexpr int kHostCopy = -1;
    struct Behind {
        std::shared_ptr<const Buffer> buffer;
        int owner = 0;              // the device whose copy is current, or kHostCopy
        uint64_t version = 0;       // of the host contents then
        std::vector<bool> devices;  // whose copies are behind
    };
    std::map<const Buffer*, Behind> m_behind;
    const bool m_trace = std::getenv("LUCENT_MULTI_TRACE") != nullptr;  // a line per launch
};

}  // namespace

std::unique_ptr<Backend> make_multi_device_backend(std::vector<std::unique_ptr<Backend>> devices,
                                                   std::vector<std::string> device_names,
                                                   unsigned piece_rows,
                                                   RunOnWorkers run_on_devices) {
    return std::make_unique<MultiDeviceBackend>(std::move(devices), std::move(device_names),
                                                piece_rows, std::move(run_on_devices));
}

}  // namespace lucent::core

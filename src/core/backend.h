// The interface every backend implements: run one launch of a compiled scene, whole or in
// pieces (the multi-device backend hands pieces to several backends, then exchanges what
// each wrote).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/compiled_scene.h"
#include "lucent/display.h"
#include "lucent/ranks.h"

namespace lucent::core {

/// Part of a launch: the launch indices with linear index (z * height + y) * width + x in
/// [first, last). In launches of more than one row both are multiples of the width.
struct LaunchPiece {
    uint64_t first = 0, last = 0;
};

/// What a launch runs.
struct LaunchSpec {
    unsigned entry = 0;
    uint3 size{1, 1, 1};
    /// Per device slot, the key device_tea_key() returns (at least one).
    std::vector<uint4> device_keys;
    uint64_t count() const { return uint64_t(size.x) * size.y * size.z; }
    /// Launches of more than one row are cut into pieces of whole rows.
    bool by_rows() const { return size.y > 1 || size.z > 1; }
    /// Called as bands of rows finish, where the device's copy is host memory; may be empty.
    std::function<void(unsigned rows_done, unsigned rows)> on_rows;
    /// Pieces handed out from outside this process's devices (the ranks' shared counter,
    /// docs/distributed.md): every device takes its pieces from here, from any thread,
    /// until it returns nothing. Empty: the backend runs the whole launch (spread over its
    /// own devices as it sees fit).
    std::function<std::optional<LaunchPiece>()> next_piece;
};

/// GPUs that share one tile counter in device memory (peer atomics over NVLink): each runs
/// the whole launch as one kernel, taking 32-index tiles from the shared counter as a
/// single GPU's threads do, so no piece ever waits for another's last tile; then each copies
/// in the tiles the others ran.
class SharedTileQueue {
  public:
    virtual ~SharedTileQueue() = default;
    /// After every device's begin_launch: starts the launch on every device.
    virtual void run(const LaunchSpec& spec) = 0;
    /// After every device's end_launch: each device gathers the others' tiles of `written`;
    /// `indices[d]` gets the launch indices device d ran.
    virtual void gather(const LaunchSpec& spec,
                        const std::vector<std::shared_ptr<const Buffer>>& written,
                        std::vector<uint64_t>& indices) = 0;
};

class Backend {
  public:
    virtual ~Backend() = default;
    /// "cpu (2 threads)", for the user.
    virtual std::string name() const = 0;
    /// One whole launch on this device: begin, one piece, end, publish the outputs.
    virtual void launch(const CompiledScene& scene, const LaunchSpec& spec, LaunchReport& report);
    /// Brings the host copy of a buffer that the last launch wrote on a device up to date.
    virtual void fetch(const Buffer& /*buffer*/) {}
    /// The buffers whose host copy is behind this device's (launches wrote them here and the
    /// host has not read them since): what must be fetched before the device is dropped
    /// (Context::set_devices). The CPU writes host storage, so it has none.
    virtual std::vector<std::shared_ptr<const Buffer>> host_copies_behind() const { return {}; }
    /// A 2D float4 buffer as an 8-bit sRGB frame (Context::display_frame): by default
    /// encoded on the host from the host copy; a GPU encodes its own copy in place.
    virtual std::shared_ptr<DisplayFrame> display_frame(const Buffer& output);

    // ---- a launch in pieces ----------------------------------------------------------------
    /// Brings this device's copy of the scene up to date (compiling its kernel if need be)
    /// and readies the launch; fills the report's compile fields.
    virtual void begin_launch(const CompiledScene& scene, const LaunchSpec& spec,
                              LaunchReport& report) = 0;
    /// Runs one piece. May return before it finished (a GPU queues a few).
    virtual void run_piece(LaunchPiece piece) = 0;
    /// Waits for every piece; adds the exceptions they raised (and kernel time) to `report`.
    virtual void end_launch(LaunchReport& report) = 0;
    /// After a one-device launch: the host copies of the buffers it may have written are
    /// this device's (fetched when the host reads them).
    virtual void publish_outputs() {}

    // ---- copies between the devices' copies of a buffer -----------------------------------
    /// True when this device's copy of a buffer is the Buffer's host storage (the CPU).
    virtual bool uses_host_storage() const { return false; }
    /// Whether this backend traverses the scene on the host (then every triangle
    /// acceleration needs its host BVH, whatever its Builder).
    virtual bool traces_on_host() const { return uses_host_storage(); }
    /// Host storage, bytes [offset, offset + bytes) → this device's copy.
    virtual void upload_range(const Buffer& /*buffer*/, size_t /*offset*/, size_t /*bytes*/) {}
    /// This device's copy → host storage.
    virtual void download_range(const Buffer& /*buffer*/, size_t /*offset*/, size_t /*bytes*/) {}
    /// Readies copies from this device to `peer` (GPUs: peer access where the pair allows).
    virtual void connect(Backend& /*peer*/) {}
    /// A tile queue shared by `devices` (this one first, all connected), or null where they
    /// cannot share one (a CPU among them, two GPUs without peer atomics).
    virtual std::unique_ptr<SharedTileQueue> share_tile_queue(
        const std::vector<Backend*>& /*devices*/) {
        return nullptr;
    }
    /// This device's copy → `target`'s copy (a peer copy between GPUs).
    virtual void copy_range_to(Backend& target, const Buffer& buffer, size_t offset,
                               size_t bytes);
};

/// The CPU backend: a worker per core (or `threads`), tiles of the launch grid. Made by the
/// backend factory (src/backends), as every backend is.
std::unique_ptr<Backend> make_cpu_backend(unsigned threads);

/// Runs job(worker) for every worker of a pool at once and returns when all are done.
using RunOnWorkers = std::function<void(const std::function<void(unsigned worker)>& job)>;

/// One launch spread over the ranks of `ranks` (docs/distributed.md): each rank runs pieces
/// on `local` (its own devices) taken from a counter shared by all ranks, and every rank's
/// copies of the launch's outputs then receive the others' pieces.
std::unique_ptr<Backend> make_distributed_backend(std::unique_ptr<Backend> local,
                                                  std::shared_ptr<Ranks> ranks);

/// One launch spread over several backends (docs/multi-device.md), each driven from a
/// worker of `run_on_devices` (one per device; the factory gives it the CPU's thread pool).
std::unique_ptr<Backend> make_multi_device_backend(std::vector<std::unique_ptr<Backend>> devices,
                                                   std::vector<std::string> device_names,
                                                   unsigned piece_rows,
                                                   RunOnWorkers run_on_devices);

}  // namespace lucent::core

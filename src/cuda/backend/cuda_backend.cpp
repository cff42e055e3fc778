// The CUDA backend (docs/architecture.md, "The CUDA backend"): at launch, if the compiled scene changed shape,
// generate the megakernel, compile it with NVRTC (or load it from the disk cache), load it
// with the driver API and run it with persistent threads.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <future>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "core/backend.h"
#include "cuda/backend/cuda_backend.h"
#include "cuda/interop/display_frame.h"
#include "cuda/backend/driver_api.h"
#include "cuda/backend/gpu_scene.h"
#include "cuda/backend/launch_shapes.h"
#include "cuda/jit/megakernel_compiler.h"
#include "cuda/jit/megakernel_generator.h"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {

constexpr unsigned kBlock = 128;  // LUCENT_GPU_BLOCK in the runtime
/// Pieces of a multi-device launch queued on a GPU at once, each on its own stream: 4, the
/// best of 4 and 8 on two H200s (docs/multi-device.md); LUCENT_GPU_PIECES_IN_FLIGHT sets
/// 1 to kMaxPiecesInFlight, for experiments.
constexpr unsigned kPiecesInFlight = 4, kMaxPiecesInFlight = 8;

constexpr int kOccupancyFirst = 0;  // shape 0: every block the registers allow
// The register-capped variant of a kernel: __launch_bounds__ for 8 blocks of 128 threads per
// SM, so at most 64 registers a thread. Measured (docs/performance.md, "The engine path
// against OptiX"): 13-17 % faster for bench rays --programs and 4-7 % for IGI, 20 % slower
// for the path tracer on Sponza; so it is one more shape for the tuning to time, not a rule.
constexpr int kCappedBlocksPerSm = 8;
// With trace() inlined, a tighter cap too: 9 blocks, at most 56 registers. On an H100 it ran
// bench rays --programs' shadow and diffuse rays 2-3 % faster than the tuning's choice
// among the other variants (docs/performance.md, session 31); one more shape to time.
constexpr int kTightCappedBlocksPerSm = 9;
std::string capped_option(int blocks_per_sm) {
    return "-DLUCENT_GPU_MIN_BLOCKS=" + std::to_string(blocks_per_sm);
}
/// The registers a thread gets with __launch_bounds__ for this many 128-thread blocks per SM
/// (the register file's 64K, in the allocation's steps of 8): 64 for 8 blocks, 56 for 9.
constexpr int capped_registers(int blocks_per_sm) {
    return 65536 / (blocks_per_sm * 128) / 8 * 8;
}
constexpr int kCappedRegisters = capped_registers(kCappedBlocksPerSm);
// The inline-trace variant (megakernel_compiler.h, can_inline_trace): trace() inlined into
// the ray-generation program where no program a trace runs traces again.
const std::string kInlineTraceOption = "-DLUCENT_GPU_INLINE_TRACE=1";
// Two of the inline-trace variants also come with lane refill (lane_refill.cuh): a lane
// whose closest-hit trace is done takes its next launch index alone and meets the lanes
// still tracing. On an H100 it ran bench rays --programs' diffuse rays 30-50 % faster and
// cost the direct sample on Sibenik 6 % and IGI's interleaved passes 3-10 % (coherent rays,
// docs/performance.md, session 33): more variants for the tuning to time, beside the
// inline-trace ones without it. Only with trace() inlined: a kernel whose traces recurse
// would meet inside nested traces, and one that never calls trace() never meets, so its
// lanes, once apart, would stay apart. LUCENT_GPU_LANE_REFILL=off leaves them out.
const std::string kLaneRefillOption = "-DLUCENT_GPU_LANE_REFILL=1";
bool lane_refill_enabled() {
    const char* v = std::getenv("LUCENT_GPU_LANE_REFILL");
    return !(v && std::strcmp(v, "off") == 0);
}

constexpr size_t kExceptionBytes = sizeof(gpu::GpuExceptionSlot) * gpu::kGpuExceptionSlots;

/// Triangles a first GPU build gets its device memory for ahead of time
/// (GpuBvhBuilder::prepare): 2^17, which holds the bunny, the dragon, Sponza and Sibenik,
/// for about 48 MB of device memory (33 MB of scratch, 16 MB of layout); a larger mesh's
/// first build allocates as before. LUCENT_GPU_BUILD_PREPARE=N sets N (0: nothing ahead),
/// for measurements.
constexpr unsigned kBuildPreparedTriangles = 1u << 17;
unsigned build_prepared_triangles() {
    const char* v = std::getenv("LUCENT_GPU_BUILD_PREPARE");
    if (!v || !*v) return kBuildPreparedTriangles;
    char* end = nullptr;
    const unsigned long n = std::strtoul(v, &end, 10);
    if (*end || n > gpu::kGpuLeafFirstMask)
        throw Error(std::string("LUCENT_GPU_BUILD_PREPARE=") + v +
                    ": expected a triangle count 0.." + std::to_string(gpu::kGpuLeafFirstMask));
    return unsigned(n);
}

class CudaBackend final : public core::Backend {
  private:
    /// One compiled variant of a ray-generation program's kernel, in its own module.
    struct KernelCode {
        CUmodule module = nullptr;
        CUfunction function = nullptr;
        CUdeviceptr params = 0;  // the module's launch parameters
        int carveout = -1;       // the carveout last set on the function
        int register_cap = 0;        // the variant's options: registers a thread at most
        bool trace_inlined = false;  // (0: as compiled), trace() inlined,
        bool lanes_refilled = false;  // lanes refilled (lane_refill.cuh)
    };
    /// A ray-generation program's kernel: its variants (0: as compiled; then, once compiled,
    /// registers capped, trace inlined, or both) and the launch shapes of all of them
    /// (launch_shapes.h).
    struct RayGenerationKernel {
        std::vector<KernelCode> codes;
        std::vector<LaunchShape> shapes{LaunchShape{}};  // shape 0: occupancy first
    };

  public:
    CudaBackend(const DriverApi& d, int ordinal, RegisterVariants register_variants,
                TreeUpgrades tree_upgrades)
        : m_driver(d),
          m_ordinal(ordinal),
          m_register_variants(register_variants),
          m_tree_upgrades(tree_upgrades) {
        check(d.cuDeviceGet(&m_device, ordinal), "cuDeviceGet");
        char name[256] = {};
        d.cuDeviceGetName(name, sizeof name, m_device);
        m_device_name = name;
        int major = 0, minor = 0;
        d.cuDeviceGetAttribute(&major, CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MAJOR, m_device);
        d.cuDeviceGetAttribute(&minor, CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MINOR, m_device);
        d.cuDeviceGetAttribute(&m_sm_count, CU_DEVICE_ATTRIBUTE_MULTIPROCESSOR_COUNT, m_device);
        m_sm = major * 10 + minor;
        check(d.cuDevicePrimaryCtxRetain(&m_context, m_device), "cuDevicePrimaryCtxRetain");
        check(d.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        // Its own stream: two devices on one GPU (a GPU listed twice) run side by side. A
        // blocking stream: the synchronous uploads on the default stream come before kernels.
        // Several: a piece queued behind another starts on the SMs the other's tail frees.
        if (const char* n = std::getenv("LUCENT_GPU_PIECES_IN_FLIGHT"))
            m_in_flight = std::clamp(unsigned(std::atoi(n)), 1u, kMaxPiecesInFlight);
        for (CUstream& s : m_streams) check(d.cuStreamCreate(&s, CU_STREAM_DEFAULT), "cuStreamCreate");
        for (CUevent& e : m_piece_done) check(d.cuEventCreate(&e, CU_EVENT_DISABLE_TIMING), "cuEventCreate");
        check(d.cuEventCreate(&m_start, CU_EVENT_DEFAULT), "cuEventCreate");
        check(d.cuEventCreate(&m_stop, CU_EVENT_DEFAULT), "cuEventCreate");
        // Page-locked staging for what every launch sends and reads back, so both are
        // queued on the launch's stream and the launch waits for the GPU once.
        void* params = nullptr;
        void* slots = nullptr;
        check(d.cuMemAllocHost(&params, sizeof(gpu::LaunchParams)), "cuMemAllocHost");
        m_params_host = static_cast<gpu::LaunchParams*>(params);
        check(d.cuMemAllocHost(&slots, kExceptionBytes), "cuMemAllocHost");
        m_slots_host = static_cast<gpu::GpuExceptionSlot*>(slots);
        // The GPU BVH builder's module (read from the kernel cache and loaded: 2 ms on an
        // H200) is made on another thread while the application sets its scene up, with
        // the device memory of a first build (GpuBvhBuilder::prepare); the first GPU build
        // takes it (errors reach that build).
        m_bvh_builder_on_the_way = std::async(
            std::launch::async, [&driver = m_driver, context = m_context, sm = m_sm,
                                 prepared = build_prepared_triangles()] {
                check(driver.cuCtxSetCurrent(context), "cuCtxSetCurrent (GPU BVH builder)");
                auto builder = std::make_unique<GpuBvhBuilder>(sm);
                try {
                    builder->prepare(prepared);
                } catch (const Error&) {
                    // Only a head start: the first build allocates what it needs itself.
                }
                return builder;
            });
    }
    ~CudaBackend() override {
        m_driver.cuCtxSetCurrent(m_context);
        m_scene.reset();
        m_bvh_builder_on_the_way = {};  // waits for it, and frees it in this context
        m_display.reset();
        for (CUevent e : m_piece_done) m_driver.cuEventDestroy(e);
        for (CUstream s : m_streams)
            if (s) m_driver.cuStreamDestroy(s);
        if (m_start) m_driver.cuEventDestroy(m_start);
        if (m_stop) m_driver.cuEventDestroy(m_stop);
        unload_kernels();
        // Freed while the context is still ours: the members' own destructors run after the
        // release below, when the last release may already have destroyed the context (its
        // memory then goes with it, but compute-sanitizer's leak check reports every block).
        m_counters.reset();
        m_exceptions.reset();
        m_scratch.reset();
        if (m_params_host) m_driver.cuMemFreeHost(m_params_host);
        if (m_slots_host) m_driver.cuMemFreeHost(m_slots_host);
        m_driver.cuDevicePrimaryCtxRelease(m_device);
    }

    std::string name() const override {
        return "cuda:" + std::to_string(m_ordinal) + " (" + m_device_name + ", sm_" +
               std::to_string(m_sm) + ")";
    }

    void begin_launch(const core::CompiledScene& scene, const core::LaunchSpec& spec,
                      LaunchReport& report) override {
        check(m_driver.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        // Trees upgraded on another thread since the last launch (TreeUpgrades::kBackground).
        const auto adopting = std::chrono::steady_clock::now();
        unsigned upgraded = m_scene ? m_scene->adopt_tree_upgrades() : 0;
        if (upgraded > 0)
            report.accel_ms += std::chrono::duration<double, std::milli>(
                                   std::chrono::steady_clock::now() - adopting)
                                   .count();
        if (!m_scene || &scene != m_last_scene || scene.generation != m_last_generation) {
            if (!m_scene)
                m_scene = std::make_unique<GpuScene>(m_sm, m_context, m_tree_upgrades,
                                                     std::move(m_bvh_builder_on_the_way));
            const auto start = std::chrono::steady_clock::now();
            m_scene->update(scene);
            upgraded += m_scene->trees_upgraded_in_update();
            report.accel_ms += m_scene->accel_ms();  // the GPU layouts (GPU or host builds)
            m_last_scene = &scene;
            m_last_generation = scene.generation;
            const auto updated = std::chrono::steady_clock::now();
            prepare_kernel(scene, report);
            if (std::getenv("LUCENT_GPU_ACCEL_TIMES"))
                std::fprintf(stderr, "lucent: GPU scene update %.3f ms, kernels %.3f ms\n",
                             std::chrono::duration<double, std::milli>(updated - start).count(),
                             std::chrono::duration<double, std::milli>(
                                 std::chrono::steady_clock::now() - updated)
                                 .count());
        } else if (upgraded > 0) {
            m_scene->update(scene);  // the flat arrays now point at the upgraded trees
        } else {
            m_scene->sync_buffers();
        }
        if (upgraded > 0) {
            // The shapes were timed on the old trees: time them again on the new ones.
            m_tuning.clear();
            report.trees_upgraded = upgraded;
        }
        if (spec.device_keys.empty() || spec.device_keys.size() > gpu::kGpuMaxDeviceSlots)
            throw Error("CUDA backend: a launch needs 1 to 16 device keys");

        gpu::LaunchParams p = m_scene->params();
        p.ray_generation = m_scene->ray_generation(spec.entry);
        p.exception = m_scene->exception(spec.entry);
        p.launch_size = spec.size;
        p.launch_count = spec.count();
        p.device_slots = unsigned(spec.device_keys.size());
        for (size_t i = 0; i < spec.device_keys.size(); ++i) p.device_keys[i] = spec.device_keys[i];
        m_counters.alloc(m_in_flight * sizeof(unsigned long long));  // one per stream
        m_exceptions.alloc(kExceptionBytes);
        p.exceptions = const_cast<gpu::GpuExceptionSlot*>(m_exceptions.as<gpu::GpuExceptionSlot>());
        // The kernel of the entry's ray-generation program (the context refuses a launch of
        // an entry without one), and its launch shape: fixed by LUCENT_GPU_CARVEOUT, else
        // tuned per entry and size.
        adopt_variants();
        m_kernel = &m_kernels.at(size_t(p.ray_generation.id));
        m_tuning_key = {spec.entry, p.launch_count};
        m_shape_trial = false;
        if (m_fixed_shape) {
            m_shape = kOccupancyFirst;
        } else {
            auto tuning = m_tuning.try_emplace(m_tuning_key, m_kernel->shapes.size()).first;
            m_shape = tuning->second.next_shape();
            m_shape_trial = tuning->second.choice() < 0;
        }
        apply_shape(*m_kernel, m_kernel->shapes[size_t(m_shape)]);
        // Scratch for the largest grid of any kernel, so launches that alternate between
        // kernels never reallocate it.
        const unsigned threads = unsigned(m_largest_grid) * kBlock;
        if (m_scratch.size() != size_t(threads) * gpu::kGpuScratchBytes)
            m_scratch.alloc(size_t(threads) * gpu::kGpuScratchBytes);
        p.scratch = const_cast<unsigned char*>(m_scratch.as<unsigned char>());
        // Queued on the first stream ahead of the start event, which the others wait for:
        // the exception slots cleared and the parameters uploaded, without a wait here.
        check(m_driver.cuMemsetD32Async(m_exceptions.ptr(), 0, kExceptionBytes / 4, m_streams[0]),
              "clear the exception slots");
        *m_params_host = p;
        check(m_driver.cuMemcpyHtoDAsync(m_code->params, m_params_host, sizeof p, m_streams[0]),
              "upload launch parameters");
        m_size = spec.size;
        m_pieces = 0;
        m_indices = 0;
        m_tiles_shared = false;
        check(m_driver.cuEventRecord(m_start, m_streams[0]), "cuEventRecord");
        for (unsigned i = 1; i < m_in_flight; ++i)
            check(m_driver.cuStreamWaitEvent(m_streams[i], m_start, 0), "cuStreamWaitEvent");
    }

    void run_piece(core::LaunchPiece piece) override {
        check(m_driver.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        // Pieces take turns on the streams, each with its counter: the counter reset, the
        // kernel over the piece, its event. Then wait for the oldest piece in flight, so the
        // pieces queued behind a running one fill the SMs its tail leaves idle (a few warps
        // on costly tiles, such as IGI's mirror pixels, can outlast a piece's other work).
        const unsigned slot = m_pieces % m_in_flight;
        m_indices += piece.last - piece.first;
        CUstream stream = m_streams[slot];
        const CUdeviceptr counter = m_counters.ptr() + slot * sizeof(unsigned long long);
        check(m_driver.cuMemsetD32Async(counter, 0, 2, stream), "reset the work counter");
        unsigned long long first = piece.first, last = piece.last;
        void* counter_arg = reinterpret_cast<void*>(counter);
        void* no_owners = nullptr;
        unsigned device = 0;
        void* args[] = {&first, &last, &counter_arg, &no_owners, &device};
        check(m_driver.cuLaunchKernel(m_code->function, unsigned(m_grid), 1, 1, kBlock, 1, 1, 0,
                                      stream, args, nullptr),
              "launch the megakernel");
        check(m_driver.cuEventRecord(m_piece_done[slot], stream), "cuEventRecord");
        if (m_pieces + 1 >= m_in_flight)
            check(m_driver.cuEventSynchronize(
                      m_piece_done[(m_pieces + 1 - m_in_flight) % m_in_flight]),
                  "run the megakernel");
        ++m_pieces;
    }

    /// The whole launch as one kernel taking tiles from a counter other GPUs share.
    void run_shared(uint64_t count, CUdeviceptr counter, CUdeviceptr owners, unsigned device) {
        check(m_driver.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        m_indices = count;
        ++m_pieces;
        m_tiles_shared = true;  // whole tiles a warp: no lane refill (lane_refill.cuh)
        unsigned long long first = 0, last = count;
        void* counter_arg = reinterpret_cast<void*>(counter);
        void* owners_arg = reinterpret_cast<void*>(owners);
        void* args[] = {&first, &last, &counter_arg, &owners_arg, &device};
        check(m_driver.cuLaunchKernel(m_code->function, unsigned(m_grid), 1, 1, kBlock, 1, 1, 0,
                                      m_streams[0], args, nullptr),
              "launch the megakernel");
    }

    /// Copies into this GPU's copy of `buffer` the tiles other GPUs ran (queued; sync()).
    void gather_tiles(const Buffer& buffer, CUdeviceptr owners, unsigned device, uint64_t tiles,
                      const gpu::DeviceCopies& copies, uint3 size) {
        check(m_driver.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        unsigned long long tile_count = tiles;
        unsigned element_bytes = unsigned(buffer.element().size);
        void* owners_arg = reinterpret_cast<void*>(owners);
        gpu::DeviceCopies by_value = copies;
        void* args[] = {&owners_arg, &device, &tile_count, &by_value, &element_bytes, &size};
        const unsigned blocks = unsigned(std::min<uint64_t>((tiles * 32 + 255) / 256, 4096));
        check(m_driver.cuLaunchKernel(m_gather, std::max(1u, blocks), 1, 1, 256, 1, 1, 0,
                                      m_streams[0], args, nullptr),
              "gather the tiles of other GPUs");
    }
    void sync() {
        check(m_driver.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        check(m_driver.cuStreamSynchronize(m_streams[0]), "gather the tiles of other GPUs");
    }
    CUdeviceptr copy_of(const Buffer& buffer) const { return mirror_of(buffer); }
    CUdevice device() const { return m_device; }
    CUcontext context() const { return m_context; }
    const DriverApi& driver_api() const { return m_driver; }

    std::unique_ptr<core::SharedTileQueue> share_tile_queue(
        const std::vector<core::Backend*>& devices) override;

    void end_launch(LaunchReport& report) override {
        check(m_driver.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        // Stop after every stream's pieces.
        for (unsigned i = 1; i < m_in_flight; ++i) {
            check(m_driver.cuEventRecord(m_piece_done[i], m_streams[i]), "cuEventRecord");
            check(m_driver.cuStreamWaitEvent(m_streams[0], m_piece_done[i], 0), "cuStreamWaitEvent");
        }
        check(m_driver.cuEventRecord(m_stop, m_streams[0]), "cuEventRecord");
        check(m_driver.cuMemcpyDtoHAsync(m_slots_host, m_exceptions.ptr(), kExceptionBytes,
                                         m_streams[0]),
              "read the exception slots");
        check(m_driver.cuStreamSynchronize(m_streams[0]), "run the megakernel");
        float kernel_ms = 0;
        m_driver.cuEventElapsedTime(&kernel_ms, m_start, m_stop);
        report.kernel_ms = kernel_ms;
        report.launch_shape_trial = m_shape_trial;
        const KernelCode& ran = m_kernel->codes.at(size_t(m_kernel->shapes[size_t(m_shape)].variant));
        report.registers_capped = ran.register_cap > 0;
        report.register_cap = unsigned(ran.register_cap);
        report.trace_inlined = ran.trace_inlined;
        report.lanes_refilled = ran.lanes_refilled && !m_tiles_shared;
        if (!m_fixed_shape && m_indices > 0)
            m_tuning.at(m_tuning_key).record(m_shape, kernel_ms / double(m_indices));

        const uint3 size = m_size;
        for (unsigned i = 0; i < gpu::kGpuExceptionSlots; ++i) {
            const gpu::GpuExceptionSlot& s = m_slots_host[i];
            if (s.code == 0) continue;
            uint64_t linear = ~s.first_linear_inverted;
            uint3 first{unsigned(linear % size.x), unsigned(linear / size.x % size.y),
                        unsigned(linear / (uint64_t(size.x) * size.y))};
            report.exceptions[s.code] = {s.count, first};
        }
    }

    void publish_outputs() override {
        m_scene->mark_outputs_device_newer();  // copied back when the host reads them
    }

    void upload_range(const Buffer& buffer, size_t offset, size_t bytes) override {
        check(m_driver.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        const auto* host = static_cast<const unsigned char*>(buffer.raw());
        check(m_driver.cuMemcpyHtoD(mirror_of(buffer) + offset, host + offset, bytes),
              "upload a piece of a buffer");
    }

    void download_range(const Buffer& buffer, size_t offset, size_t bytes) override {
        check(m_driver.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        auto* host = static_cast<unsigned char*>(const_cast<void*>(buffer.raw()));
        check(m_driver.cuMemcpyDtoH(host + offset, mirror_of(buffer) + offset, bytes),
              "download a piece of a buffer");
        buffer.mark_written();
    }

    void copy_range_to(core::Backend& target, const Buffer& buffer, size_t offset,
                       size_t bytes) override {
        auto* gpu = dynamic_cast<CudaBackend*>(&target);
        if (!gpu) return core::Backend::copy_range_to(target, buffer, offset, bytes);
        // GPU to GPU: directly over NVLink or PCIe where peer access is on (connect()), else
        // the driver stages it through host memory.
        check(m_driver.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        check(m_driver.cuMemcpyPeer(gpu->mirror_of(buffer) + offset, gpu->m_context,
                                    mirror_of(buffer) + offset, m_context, bytes),
              "copy a piece of a buffer between GPUs");
    }

    void connect(core::Backend& peer) override {
        auto* gpu = dynamic_cast<CudaBackend*>(&peer);
        if (!gpu || gpu->m_device == m_device) return;
        int can = 0;
        m_driver.cuDeviceCanAccessPeer(&can, m_device, gpu->m_device);
        if (!can) return;
        check(m_driver.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        CUresult r = m_driver.cuCtxEnablePeerAccess(gpu->m_context, 0);
        if (r != CUDA_ERROR_PEER_ACCESS_ALREADY_ENABLED) check(r, "enable peer access");
        if (std::getenv("LUCENT_MULTI_TRACE"))
            std::fprintf(stderr, "multi-device: %s reaches %s directly (peer access)\n",
                         name().c_str(), gpu->name().c_str());
    }

    std::shared_ptr<DisplayFrame> display_frame(const Buffer& output) override {
        check(m_driver.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        const CUdeviceptr linear = m_scene ? m_scene->current_mirror(output) : 0;
        if (!linear) return core::Backend::display_frame(output);  // the host copy is newer
        if (!m_display) m_display = std::make_unique<DisplayEncoder>(m_device, m_sm);
        return m_display->encode(linear, output.size().x, output.size().y);
    }

    void fetch(const Buffer& buffer) override {
        check(m_driver.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        if (m_scene) m_scene->fetch(buffer);
    }

    std::vector<std::shared_ptr<const Buffer>> host_copies_behind() const override {
        return m_scene ? m_scene->device_newer_buffers()
                       : std::vector<std::shared_ptr<const Buffer>>{};
    }

    /// Generates the kernels for this scene; compiles them only when the source changed.
    void prepare_kernel(const core::CompiledScene& scene, LaunchReport& report) {
        Megakernel kernel = generate_megakernel(scene, m_scene->programs());
        std::string text = kernel.text();
        if (text == m_source && !m_kernels.empty()) return;  // same shape: keep the kernels
        compile_megakernel(kernel, m_sm);
        report.jit_ms = kernel.jit_ms;
        report.jit_cached = kernel.from_cache;
        const KernelShape& shape = kernel.shape;

        unload_kernels();
        const char* fixed = std::getenv("LUCENT_GPU_CARVEOUT");  // tuning experiments
        m_fixed_shape = fixed != nullptr;
        m_kernels.resize(kernel.binaries.size());
        m_largest_grid = 1;
        for (size_t i = 0; i < m_kernels.size(); ++i) {
            RayGenerationKernel& k = m_kernels[i];
            k.codes.push_back(load_code(kernel.binaries[i].cubin, i));
            k.shapes = launch_shapes(k.codes[0].function, fixed);
            for (const LaunchShape& s : k.shapes) m_largest_grid = std::max(m_largest_grid, s.grid);
        }
        if (!m_kernels.empty())  // every module has it: the first's serves
            check(m_driver.cuModuleGetFunction(&m_gather, m_kernels[0].codes[0].module,
                                               "lucent_gather_tiles"),
                  "find lucent_gather_tiles");
        m_tuning.clear();
        // Recursion (trace from closest hit) runs on the thread's stack: one frame per depth.
        size_t stack = 1024 + size_t(shape.max_depth) * (2 * shape.attribute_bytes + 1536);
        check(m_driver.cuCtxSetLimit(CU_LIMIT_STACK_SIZE, stack), "set the stack size");
        m_source = std::move(text);
        start_variants(kernel);
    }

    /// A compiled kernel loaded as its own module.
    KernelCode load_code(const std::string& cubin, size_t kernel) {
        KernelCode code;
        check(m_driver.cuModuleLoadData(&code.module, cubin.data()), "load the megakernel");
        const std::string name = ray_generation_kernel(int(kernel));
        check(m_driver.cuModuleGetFunction(&code.function, code.module, name.c_str()),
              ("find " + name).c_str());
        size_t bytes = 0;
        check(
            m_driver.cuModuleGetGlobal(&code.params, &bytes, code.module, "_ZN6lucent3gpu6paramsE"),
            "find the launch parameters");
        return code;
    }

    /// Compiles the variants of each kernel, on other threads while launches run
    /// (ContextOptions::register_variants, or LUCENT_GPU_REGISTER_VARIANTS: "sync" compiles
    /// them here, "off" not at all): registers capped where the kernel uses more than the
    /// cap allows, trace() inlined where its trace_ray is not recursive, and both where both
    /// hold. adopt_variants adds them to the kernels' shapes. Not with a fixed carveout, or
    /// a block count or the inlining in LUCENT_NVRTC_OPTIONS (experiments that choose the
    /// shape or the code themselves).
    void start_variants(const Megakernel& kernel) {
        const char* mode_env = std::getenv("LUCENT_GPU_REGISTER_VARIANTS");
        const std::string mode = mode_env && *mode_env ? mode_env
                                 : m_register_variants == RegisterVariants::kOff ? "off"
                                 : m_register_variants == RegisterVariants::kWithKernel
                                     ? "sync"
                                     : "background";
        const char* options = std::getenv("LUCENT_NVRTC_OPTIONS");
        if (mode == "off" || m_fixed_shape ||
            (options && (std::strstr(options, "LUCENT_GPU_MIN_BLOCKS") ||
                         std::strstr(options, "LUCENT_GPU_INLINE_TRACE"))))
            return;
        m_variants.clear();
        std::vector<CompileRequest> requests;
        const bool refill = lane_refill_enabled();
        for (size_t i = 0; i < m_kernels.size(); ++i) {
            int registers = 0;
            m_driver.cuFuncGetAttribute(&registers, CU_FUNC_ATTRIBUTE_NUM_REGS,
                                        m_kernels[i].codes[0].function);
            const bool cap = registers > kCappedRegisters;
            const bool inline_trace = can_inline_trace(kernel.binaries.at(i));
            auto add = [&](int capped_blocks, bool inlined, bool refilled) {
                std::vector<std::string> extra;
                if (capped_blocks > 0) extra.push_back(capped_option(capped_blocks));
                if (inlined) extra.push_back(kInlineTraceOption);
                if (refilled) extra.push_back(kLaneRefillOption);
                requests.push_back(std::move(unit_requests(kernel, m_sm, {i}, extra).at(0)));
                m_variants.push_back({i, capped_blocks, inlined, refilled});
            };
            if (cap) add(kCappedBlocksPerSm, false, false);
            if (inline_trace) add(0, true, false);
            if (inline_trace && refill) add(0, true, true);
            if (cap && inline_trace) add(kCappedBlocksPerSm, true, false);
            if (inline_trace) add(kTightCappedBlocksPerSm, true, false);
            if (inline_trace && refill) add(kTightCappedBlocksPerSm, true, true);
        }
        if (m_variants.empty()) return;
        if (mode == "sync") {
            std::vector<CompileResult> binaries;
            try {
                binaries = compile_units(requests);
            } catch (const std::exception&) {
                m_variants.clear();  // as in the background: the kernels as compiled run
                return;
            }
            adopt(binaries);
            return;
        }
        m_variants_compiling = std::async(
            std::launch::async, [requests = std::move(requests)] { return compile_units(requests); });
    }

    /// At a launch's start: the variants, once compiled, become shapes of their kernels. If
    /// one failed to compile, none is added (the kernels as compiled run).
    void adopt_variants() {
        if (!m_variants_compiling.valid() ||
            m_variants_compiling.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
            return;
        std::vector<CompileResult> binaries;
        try {
            binaries = m_variants_compiling.get();
        } catch (const std::exception&) {
            m_variants.clear();
            return;
        }
        adopt(binaries);
    }

    void adopt(const std::vector<CompileResult>& binaries) {
        for (size_t j = 0; j < binaries.size() && j < m_variants.size(); ++j) {
            const Variant& v = m_variants[j];
            RayGenerationKernel& k = m_kernels[v.kernel];
            KernelCode code = load_code(binaries[j].cubin, v.kernel);
            code.register_cap = v.capped_blocks > 0 ? capped_registers(v.capped_blocks) : 0;
            code.trace_inlined = v.trace_inlined;
            code.lanes_refilled = v.lanes_refilled;
            std::vector<LaunchShape> shapes = launch_shapes(code.function, nullptr);
            for (LaunchShape& shape : shapes) {
                shape.variant = int(k.codes.size());
                m_largest_grid = std::max(m_largest_grid, shape.grid);
            }
            k.codes.push_back(code);
            k.shapes.insert(k.shapes.end(), shapes.begin(), shapes.end());
            // Entries already tuned time the new shapes too.
            for (auto& [key, tuning] : m_tuning)
                if (size_t(m_scene->ray_generation(key.first).id) == v.kernel)
                    tuning.add_shapes(shapes.size());
        }
        m_variants.clear();
    }

    void unload_kernels() {
        if (m_variants_compiling.valid()) m_variants_compiling.wait();  // of these kernels
        m_variants_compiling = {};
        m_variants.clear();
        for (RayGenerationKernel& k : m_kernels)
            for (KernelCode& code : k.codes)
                if (code.module) m_driver.cuModuleUnload(code.module);
        m_kernels.clear();
        m_kernel = nullptr;
        m_code = nullptr;
        m_gather = nullptr;
        m_source.clear();
    }

  private:
    CUdeviceptr mirror_of(const Buffer& buffer) const {
        CUdeviceptr ptr = m_scene ? m_scene->mirror(buffer) : 0;
        if (!ptr)
            throw Error("CUDA backend: " + buffer.describe() + " has no copy on " + name());
        return ptr;
    }

    /// The launch shapes of `kernel` (launch_shapes.h): for each count of blocks per SM up to
    /// what its registers allow, just the shared memory those blocks need (the runtime's
    /// per-thread state, 6 KB a block) and the rest as L1 for the trace frames in local
    /// memory; only `fixed` (LUCENT_GPU_CARVEOUT) when it is set.
    std::vector<LaunchShape> launch_shapes(CUfunction kernel, const char* fixed) {
        int static_shared = 0, reserved = 0, shared_per_sm = 0;
        m_driver.cuFuncGetAttribute(&static_shared, CU_FUNC_ATTRIBUTE_SHARED_SIZE_BYTES, kernel);
        m_driver.cuDeviceGetAttribute(
            &reserved, CU_DEVICE_ATTRIBUTE_RESERVED_SHARED_MEMORY_PER_BLOCK, m_device);
        m_driver.cuDeviceGetAttribute(
            &shared_per_sm, CU_DEVICE_ATTRIBUTE_MAX_SHARED_MEMORY_PER_MULTIPROCESSOR, m_device);
        std::vector<LaunchShape> shapes;
        if (fixed) {
            shapes.push_back({std::atoi(fixed), 0});
        } else {
            // Shared memory is no limit at a carveout of 100 %.
            const int by_registers = resident_blocks(kernel, 100);
            const SharedMemoryNeeds needs{static_shared, reserved, shared_per_sm};
            for (int carveout : launch_shape_carveouts(
                     by_registers, needs, [&](int c) { return resident_blocks(kernel, c); }))
                shapes.push_back({carveout, 0});
        }
        for (LaunchShape& shape : shapes)
            shape.grid = resident_blocks(kernel, shape.carveout) * m_sm_count;
        return shapes;
    }

    /// Blocks of `kernel` resident per SM with this carveout (which it leaves set: the
    /// kernel's applied shape is reset by launch_shapes' caller).
    int resident_blocks(CUfunction kernel, int carveout) {
        check(m_driver.cuFuncSetAttribute(
                  kernel, CU_FUNC_ATTRIBUTE_PREFERRED_SHARED_MEMORY_CARVEOUT, carveout),
              "set the shared memory carveout");
        int blocks = 0;
        check(m_driver.cuOccupancyMaxActiveBlocksPerMultiprocessor(&blocks, kernel, kBlock, 0),
              "occupancy");
        return std::max(1, blocks);
    }

    /// The variant and grid of `shape` for this launch, with its carveout set.
    void apply_shape(RayGenerationKernel& kernel, const LaunchShape& shape) {
        m_code = &kernel.codes.at(size_t(shape.variant));
        m_grid = shape.grid;
        if (shape.carveout == m_code->carveout) return;
        check(m_driver.cuFuncSetAttribute(m_code->function,
                                          CU_FUNC_ATTRIBUTE_PREFERRED_SHARED_MEMORY_CARVEOUT,
                                          shape.carveout),
              "set the shared memory carveout");
        m_code->carveout = shape.carveout;
    }

    const DriverApi& m_driver;
    int m_ordinal = 0;
    CUdevice m_device = 0;
    CUstream m_streams[kMaxPiecesInFlight] = {};
    CUevent m_piece_done[kMaxPiecesInFlight] = {};
    unsigned m_in_flight = kPiecesInFlight;
    unsigned m_pieces = 0;   // of the current launch
    uint64_t m_indices = 0;  // launch indices in them
    uint3 m_size{1, 1, 1};
    int m_shape = kOccupancyFirst;
    bool m_shape_trial = false;  // this launch times a shape for the tuning
    std::pair<unsigned, uint64_t> m_tuning_key{0, 0};
    CUcontext m_context = nullptr;
    std::vector<RayGenerationKernel> m_kernels;  // by ray-generation program (ProgramTable id)
    RayGenerationKernel* m_kernel = nullptr;      // the current launch's
    KernelCode* m_code = nullptr;                 // its variant in this launch's shape
    int m_grid = 1;                               // and that shape's grid
    /// A kernel's variant being compiled: which kernel, and how it is compiled.
    struct Variant {
        size_t kernel = 0;
        int capped_blocks = 0;  // __launch_bounds__' blocks per SM (0: none)
        bool trace_inlined = false;
        bool lanes_refilled = false;
    };
    std::future<std::vector<CompileResult>> m_variants_compiling;
    std::vector<Variant> m_variants;  // what m_variants_compiling compiles, in its order
    RegisterVariants m_register_variants;
    TreeUpgrades m_tree_upgrades;
    // The GPU BVH builder being made on another thread, until a GpuScene takes it.
    std::future<std::unique_ptr<GpuBvhBuilder>> m_bvh_builder_on_the_way;
    int m_largest_grid = 1;                       // of every kernel's shapes
    CUfunction m_gather = nullptr;
    std::string m_device_name, m_source;
    int m_sm = 0, m_sm_count = 0;
    std::unique_ptr<GpuScene> m_scene;
    std::unique_ptr<DisplayEncoder> m_display;  // made by the first display_frame
    bool m_fixed_shape = false;
    bool m_tiles_shared = false;  // this launch took tiles from a counter other GPUs share
    std::map<std::pair<unsigned, uint64_t>, ShapeTuning> m_tuning;  // by entry, launch count
    const core::CompiledScene* m_last_scene = nullptr;
    uint64_t m_last_generation = 0;
    DeviceBuffer m_counters, m_exceptions, m_scratch;
    CUevent m_start = nullptr, m_stop = nullptr;
    gpu::LaunchParams* m_params_host = nullptr;      // page-locked
    gpu::GpuExceptionSlot* m_slots_host = nullptr;  // page-locked, kGpuExceptionSlots
};

/// The tile counter and the tile owners live on the first GPU; the others reach them by
/// peer access (the same address works on every GPU of the group).
class GpuSharedTileQueue final : public core::SharedTileQueue {
  public:
    explicit GpuSharedTileQueue(std::vector<CudaBackend*> gpus) : m_gpus(std::move(gpus)) {}
    ~GpuSharedTileQueue() override {
        m_gpus[0]->driver_api().cuCtxSetCurrent(m_gpus[0]->context());  // frees on the first GPU
        m_counter.reset();
        m_owners.reset();
        for (unsigned d = 1; d < m_local_owners.size(); ++d) {
            m_gpus[d]->driver_api().cuCtxSetCurrent(m_gpus[d]->context());
            m_local_owners[d].reset();
        }
    }

    void run(const core::LaunchSpec& spec) override {
        CudaBackend& first = *m_gpus[0];
        check(first.driver_api().cuCtxSetCurrent(first.context()), "cuCtxSetCurrent");
        const uint64_t tiles = tile_count(spec);
        if (m_owners.size() < tiles) m_owners.alloc(tiles);
        m_counter.alloc(sizeof(unsigned long long));
        m_counter.fill(0);  // synchronous: done before any GPU starts
        for (unsigned d = 0; d < m_gpus.size(); ++d)
            m_gpus[d]->run_shared(spec.count(), m_counter.ptr(), m_owners.ptr(), d);
    }

    void gather(const core::LaunchSpec& spec,
                const std::vector<std::shared_ptr<const Buffer>>& written,
                std::vector<uint64_t>& indices) override {
        const uint64_t tiles = tile_count(spec);
        // Each GPU reads the owners from its own memory: one peer copy, not a peer read per
        // element.
        m_local_owners.resize(m_gpus.size());
        for (unsigned d = 1; d < m_gpus.size() && !written.empty(); ++d) {
            CudaBackend& gpu = *m_gpus[d];
            check(gpu.driver_api().cuCtxSetCurrent(gpu.context()), "cuCtxSetCurrent");
            if (m_local_owners[d].size() < tiles) m_local_owners[d].alloc(tiles);
            check(gpu.driver_api().cuMemcpyPeer(m_local_owners[d].ptr(), gpu.context(),
                                                m_owners.ptr(), m_gpus[0]->context(), tiles),
                  "copy the tile owners between GPUs");
        }
        for (const auto& buffer : written) {
            gpu::DeviceCopies copies{};
            for (unsigned d = 0; d < m_gpus.size(); ++d) copies.base[d] = m_gpus[d]->copy_of(*buffer);
            for (unsigned d = 0; d < m_gpus.size(); ++d)
                m_gpus[d]->gather_tiles(*buffer, d ? m_local_owners[d].ptr() : m_owners.ptr(), d,
                                        tiles, copies, spec.size);
        }
        for (CudaBackend* gpu : m_gpus) gpu->sync();
        // Who ran what, for the report.
        CudaBackend& first = *m_gpus[0];
        check(first.driver_api().cuCtxSetCurrent(first.context()), "cuCtxSetCurrent");
        std::vector<unsigned char> owners(tiles);
        m_owners.download(owners.data(), tiles);
        indices.assign(m_gpus.size(), 0);
        const uint3 s = spec.size;
        const uint64_t rows = uint64_t(s.y) * s.z, tiles_x = (s.x + 7) / 8;
        for (uint64_t t = 0; t < tiles; ++t) {
            uint64_t n;
            if (spec.by_rows())
                n = std::min<uint64_t>(8, s.x - (t % tiles_x) * 8) *
                    std::min<uint64_t>(4, rows - (t / tiles_x) * 4);
            else
                n = std::min<uint64_t>(32, spec.count() - t * 32);
            if (owners[t] < indices.size()) indices[owners[t]] += n;
        }
    }

  private:
    /// The megakernel's tiles: 8x4 over the rows of a launch of several rows, else 32.
    static uint64_t tile_count(const core::LaunchSpec& spec) {
        if (!spec.by_rows()) return (spec.count() + 31) / 32;
        const uint64_t rows = uint64_t(spec.size.y) * spec.size.z;
        return ((spec.size.x + 7) / 8) * ((rows + 3) / 4);
    }

    std::vector<CudaBackend*> m_gpus;
    DeviceBuffer m_counter, m_owners;        // on the first GPU
    std::vector<DeviceBuffer> m_local_owners;  // the owners copied to each other GPU
};

std::unique_ptr<core::SharedTileQueue> CudaBackend::share_tile_queue(
    const std::vector<core::Backend*>& devices) {
    std::vector<CudaBackend*> gpus;
    for (core::Backend* b : devices) {
        auto* gpu = dynamic_cast<CudaBackend*>(b);
        if (!gpu) return nullptr;  // a CPU cannot take tiles from a counter in GPU memory
        gpus.push_back(gpu);
    }
    // Every pair of GPUs needs peer atomics (NVLink). A GPU listed twice gains nothing from
    // sharing: its first kernel would fill it and take every tile; its two devices take
    // pieces from the host queue instead, and both run.
    for (CudaBackend* a : gpus)
        for (CudaBackend* b : gpus) {
            if (a == b) continue;
            if (a->device() == b->device()) return nullptr;
            int access = 0, atomics = 0;
            m_driver.cuDeviceCanAccessPeer(&access, a->device(), b->device());
            m_driver.cuDeviceGetP2PAttribute(
                &atomics, CU_DEVICE_P2P_ATTRIBUTE_NATIVE_ATOMIC_SUPPORTED, a->device(), b->device());
            if (!access || !atomics) return nullptr;
        }
    if (gpus.empty() || gpus[0] != this) return nullptr;
    return std::make_unique<GpuSharedTileQueue>(std::move(gpus));
}

}  // namespace

std::unique_ptr<core::Backend> make_cuda_backend(int ordinal, std::string* why,
                                                 RegisterVariants register_variants,
                                                 TreeUpgrades tree_upgrades) {
    const DriverApi* d = driver(why);
    if (!d) return nullptr;
    std::string nvrtc_why;
    if (nvrtc_version(&nvrtc_why).empty()) {
        if (why) *why = nvrtc_why;
        return nullptr;
    }
    int count = 0;
    d->cuDeviceGetCount(&count);
    if (ordinal < 0 || ordinal >= count) {
        if (why)
            *why = "there is no GPU " + std::to_string(ordinal) + " (the driver reports " +
                   std::to_string(count) + ")";
        return nullptr;
    }
    return std::make_unique<CudaBackend>(*d, ordinal, register_variants, tree_upgrades);
}

int gpu_count() {
    const DriverApi* d = driver();
    int count = 0;
    if (d) d->cuDeviceGetCount(&count);
    return count;
}

}  // namespace lucent::cuda

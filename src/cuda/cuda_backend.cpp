// The CUDA backend (ARCHITECTURE §4): at launch, if the compiled scene changed shape,
// generate the megakernel, compile it with NVRTC (or load it from the disk cache), load it
// with the driver API and run it with persistent threads.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <utility>

#include "core/backend.h"
#include "cuda/cuda_backend.h"
#include "cuda/driver_api.h"
#include "cuda/gpu_scene.h"
#include "cuda/megakernel_compiler.h"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {

constexpr unsigned kBlock = 128;  // LUCENT_GPU_BLOCK in the runtime

/// How the megakernel is launched: the share of the SM's on-chip memory given to shared
/// memory (the rest is L1) and the persistent grid that share lets run at once.
struct LaunchShape {
    int carveout = 0;  // percent of the largest shared-memory configuration
    int grid = 1;      // blocks: resident blocks per SM x SMs
};

/// The two shapes the backend chooses between for each entry point and launch size.
/// Measured on the H100 (docs/performance.md): IGI, the path tracer and the fog run 2 to 2.7
/// times faster with every block the registers allow resident; the Whitted sample, whose
/// deep recursion keeps large trace frames in local memory, runs 1.2 times faster with one
/// block per SM and all of L1 for them. Neither is right for every program, so the first
/// launches try both.
enum : int { kOccupancyFirst = 0, kL1First = 1 };

/// Per entry point and launch size: launch 1 runs the occupancy-first shape (and warms up),
/// launch 2 the L1-first, launch 3 the occupancy-first again; from then on, the faster of
/// launches 2 and 3.
struct ShapeTuning {
    unsigned launches = 0;
    double ms[2] = {0, 0};
    int choice = -1;

    int next_shape() const {
        if (choice >= 0) return choice;
        return launches == 1 ? kL1First : kOccupancyFirst;
    }
    void record(int shape, double kernel_ms) {
        if (choice >= 0) return;
        if (launches >= 1) ms[shape] = kernel_ms;
        if (++launches == 3)
            choice = ms[kL1First] < ms[kOccupancyFirst] ? kL1First : kOccupancyFirst;
    }
};

class CudaBackend final : public core::Backend {
  public:
    explicit CudaBackend(const DriverApi& d) : m_driver(d) {
        check(d.cuDeviceGet(&m_device, 0), "cuDeviceGet");
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
    }
    ~CudaBackend() override {
        m_scene.reset();
        if (m_start) m_driver.cuEventDestroy(m_start);
        if (m_stop) m_driver.cuEventDestroy(m_stop);
        if (m_module) m_driver.cuModuleUnload(m_module);
        m_driver.cuDevicePrimaryCtxRelease(m_device);
    }

    std::string name() const override {
        return "cuda (" + m_device_name + ", sm_" + std::to_string(m_sm) + ")";
    }

    void launch(const core::CompiledScene& scene, unsigned entry, uint3 size,
                LaunchReport& report) override {
        check(m_driver.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        if (!m_scene || &scene != m_last_scene || scene.generation != m_last_generation) {
            if (!m_scene) m_scene = std::make_unique<GpuScene>();
            m_scene->update(scene);
            m_last_scene = &scene;
            m_last_generation = scene.generation;
            prepare_kernel(scene, report);
        } else {
            m_scene->sync_buffers();
        }

        gpu::LaunchParams p = m_scene->params();
        p.ray_generation = m_scene->ray_generation(entry);
        p.exception = m_scene->exception(entry);
        p.launch_size = size;
        p.launch_count = uint64_t(size.x) * size.y * size.z;
        m_counter.alloc(sizeof(unsigned long long));
        m_counter.fill(0);
        m_exceptions.alloc(sizeof(gpu::GpuExceptionSlot) * gpu::kGpuExceptionSlots);
        m_exceptions.fill(0);
        p.work_counter = const_cast<unsigned long long*>(m_counter.as<unsigned long long>());
        p.exceptions = const_cast<gpu::GpuExceptionSlot*>(m_exceptions.as<gpu::GpuExceptionSlot>());
        // The launch shape: fixed by LUCENT_GPU_CARVEOUT, else tuned per entry and size.
        ShapeTuning& tuning = m_tuning[{entry, p.launch_count}];
        const int shape = m_fixed_shape ? kOccupancyFirst : tuning.next_shape();
        apply_shape(m_shapes[shape]);
        const unsigned threads = unsigned(std::max(m_shapes[0].grid, m_shapes[1].grid)) * kBlock;
        if (m_scratch.size() != size_t(threads) * gpu::kGpuScratchBytes)
            m_scratch.alloc(size_t(threads) * gpu::kGpuScratchBytes);
        p.scratch = const_cast<unsigned char*>(m_scratch.as<unsigned char>());
        check(m_driver.cuMemcpyHtoD(m_params_global, &p, sizeof p), "upload launch parameters");

        if (!m_start) {
            check(m_driver.cuEventCreate(&m_start, CU_EVENT_DEFAULT), "cuEventCreate");
            check(m_driver.cuEventCreate(&m_stop, CU_EVENT_DEFAULT), "cuEventCreate");
        }
        check(m_driver.cuEventRecord(m_start, nullptr), "cuEventRecord");
        check(m_driver.cuLaunchKernel(m_kernel, unsigned(m_applied.grid), 1, 1, kBlock, 1, 1, 0,
                                      nullptr, nullptr, nullptr),
              "launch the megakernel");
        check(m_driver.cuEventRecord(m_stop, nullptr), "cuEventRecord");
        check(m_driver.cuCtxSynchronize(), "run the megakernel");
        float kernel_ms = 0;
        m_driver.cuEventElapsedTime(&kernel_ms, m_start, m_stop);
        report.kernel_ms = kernel_ms;
        if (!m_fixed_shape) tuning.record(shape, kernel_ms);

        std::vector<gpu::GpuExceptionSlot> slots(gpu::kGpuExceptionSlots);
        m_exceptions.download(slots.data(), slots.size() * sizeof slots[0]);
        for (const auto& s : slots) {
            if (s.code == 0) continue;
            uint64_t linear = ~s.first_linear_inverted;
            uint3 first{unsigned(linear % size.x), unsigned(linear / size.x % size.y),
                        unsigned(linear / (uint64_t(size.x) * size.y))};
            report.exceptions[s.code] = {s.count, first};
        }
        m_scene->mark_outputs_device_newer();  // copied back when the host reads them
    }

    void fetch(const Buffer& buffer) override {
        check(m_driver.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
        if (m_scene) m_scene->fetch(buffer);
    }

    /// Generates the kernel for this scene; compiles it only when the source changed.
    void prepare_kernel(const core::CompiledScene& scene, LaunchReport& report) {
        Megakernel kernel = generate_megakernel(scene, m_scene->programs());
        if (kernel.source == m_source && m_module) return;  // same shape: keep the kernel
        compile_megakernel(kernel, m_sm);
        report.jit_ms = kernel.binary.ms;
        report.jit_cached = kernel.binary.from_cache;
        const KernelShape& shape = kernel.shape;
        const CompileResult& compiled = kernel.binary;

        if (m_module) m_driver.cuModuleUnload(m_module);
        m_module = nullptr;
        check(m_driver.cuModuleLoadData(&m_module, compiled.cubin.data()), "load the megakernel");
        check(m_driver.cuModuleGetFunction(&m_kernel, m_module, "lucent_megakernel"),
              "find lucent_megakernel");
        size_t bytes = 0;
        check(m_driver.cuModuleGetGlobal(&m_params_global, &bytes, m_module,
                                         "_ZN6lucent3gpu6paramsE"),
              "find the launch parameters");
        // Two launch shapes (see LaunchShape and ShapeTuning). Occupancy first: as many
        // blocks per SM as the registers allow, with just the shared memory they need (the
        // runtime's per-thread state, 5 KB a block) and the rest as L1. L1 first: shared
        // memory for one block, everything else L1 for the trace frames in local memory.
        const char* fixed = std::getenv("LUCENT_GPU_CARVEOUT");  // tuning experiments
        m_fixed_shape = fixed != nullptr;
        int static_shared = 0, reserved = 0, shared_per_sm = 0;
        m_driver.cuFuncGetAttribute(&static_shared, CU_FUNC_ATTRIBUTE_SHARED_SIZE_BYTES, m_kernel);
        m_driver.cuDeviceGetAttribute(
            &reserved, CU_DEVICE_ATTRIBUTE_RESERVED_SHARED_MEMORY_PER_BLOCK, m_device);
        m_driver.cuDeviceGetAttribute(
            &shared_per_sm, CU_DEVICE_ATTRIBUTE_MAX_SHARED_MEMORY_PER_MULTIPROCESSOR, m_device);
        const int by_registers = resident_blocks(100);  // shared memory is no limit at 100 %
        const int needed = by_registers * (static_shared + reserved);
        const int fit = shared_per_sm > 0
                            ? std::min(100, (100 * needed + shared_per_sm - 1) / shared_per_sm + 1)
                            : 100;
        m_shapes[kOccupancyFirst] = {fixed ? std::atoi(fixed) : fit, 0};
        m_shapes[kL1First] = {0, 0};
        for (LaunchShape& shape : m_shapes)
            shape.grid = resident_blocks(shape.carveout) * m_sm_count;
        m_applied = {-1, 0};
        m_tuning.clear();
        // Recursion (trace from closest hit) runs on the thread's stack: one frame per depth.
        size_t stack = 1024 + size_t(shape.max_depth) * (2 * shape.attribute_bytes + 1536);
        check(m_driver.cuCtxSetLimit(CU_LIMIT_STACK_SIZE, stack), "set the stack size");
        m_source = std::move(kernel.source);
    }

  private:
    /// Blocks of the megakernel resident per SM with this carveout.
    int resident_blocks(int carveout) {
        check(m_driver.cuFuncSetAttribute(
                  m_kernel, CU_FUNC_ATTRIBUTE_PREFERRED_SHARED_MEMORY_CARVEOUT, carveout),
              "set the shared memory carveout");
        m_applied = {-1, 0};
        int blocks = 0;
        check(m_driver.cuOccupancyMaxActiveBlocksPerMultiprocessor(&blocks, m_kernel, kBlock, 0),
              "occupancy");
        return std::max(1, blocks);
    }

    void apply_shape(const LaunchShape& shape) {
        if (shape.carveout == m_applied.carveout) return;
        check(m_driver.cuFuncSetAttribute(
                  m_kernel, CU_FUNC_ATTRIBUTE_PREFERRED_SHARED_MEMORY_CARVEOUT, shape.carveout),
              "set the shared memory carveout");
        m_applied = shape;
    }

    const DriverApi& m_driver;
    CUdevice m_device = 0;
    CUcontext m_context = nullptr;
    CUmodule m_module = nullptr;
    CUfunction m_kernel = nullptr;
    CUdeviceptr m_params_global = 0;
    std::string m_device_name, m_source;
    int m_sm = 0, m_sm_count = 0;
    std::unique_ptr<GpuScene> m_scene;
    LaunchShape m_shapes[2], m_applied{-1, 0};
    bool m_fixed_shape = false;
    std::map<std::pair<unsigned, uint64_t>, ShapeTuning> m_tuning;  // by entry, launch count
    const core::CompiledScene* m_last_scene = nullptr;
    uint64_t m_last_generation = 0;
    DeviceBuffer m_counter, m_exceptions, m_scratch;
    CUevent m_start = nullptr, m_stop = nullptr;
};

}  // namespace

std::unique_ptr<core::Backend> make_cuda_backend(std::string* why) {
    const DriverApi* d = driver(why);
    if (!d) return nullptr;
    std::string nvrtc_why;
    if (nvrtc_version(&nvrtc_why).empty()) {
        if (why) *why = nvrtc_why;
        return nullptr;
    }
    return std::make_unique<CudaBackend>(*d);
}

}  // namespace lucent::cuda

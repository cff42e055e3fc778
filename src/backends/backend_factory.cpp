#include "backends/backend_factory.h"

#include <utility>
#include <vector>

#include "cpu/thread_pool.h"
#include "lucent/error.h"
#if LUCENT_HAVE_CUDA
#include "cuda/backend/cuda_backend.h"
#include "cuda/interop/gl_texture_interop.h"
#include "cuda/jit/megakernel_compiler.h"
#endif

namespace lucent::core {

namespace {

/// One device of a device list.
std::unique_ptr<Backend> make_device_backend(const DeviceSpec& device,
                                             const ContextOptions& options) {
    if (device.kind == DeviceSpec::Kind::kCpu) return make_cpu_backend(options.threads);
#if LUCENT_HAVE_CUDA
    std::string why;
    if (auto backend = cuda::make_cuda_backend(device.ordinal, &why, options.register_variants,
                                               options.tree_upgrades))
        return backend;
    throw Error("Context: device " + device_spec_name(device) + " cannot run here: " + why +
                "; list the GPUs `nvidia-smi -L` shows, or cpu");
#else
    throw Error("Context: device " + device_spec_name(device) +
                " needs the CUDA backend, which is not part of this build (it needs the CUDA "
                "toolkit at configure time); use the device cpu");
#endif
}

/// The multi-device backend drives each device from a worker of a pool of its own.
RunOnWorkers worker_pool(unsigned workers) {
    auto pool = std::make_shared<cpu::ThreadPool>(workers);
    return [pool](const std::function<void(unsigned)>& job) { pool->run(job); };
}

}  // namespace

namespace {
/// This process's devices: the multi-device backend over options.devices, or one device.
std::unique_ptr<Backend> make_local_backend(const ContextOptions& options, std::string& notice) {
    if (!options.devices.empty()) {
        std::vector<std::unique_ptr<Backend>> devices;
        std::vector<std::string> names;
        for (const DeviceSpec& device : options.devices) {
            devices.push_back(make_device_backend(device, options));
            names.push_back(device_spec_name(device));
        }
        const unsigned count = unsigned(devices.size());
        return make_multi_device_backend(std::move(devices), std::move(names), options.piece_rows,
                                         worker_pool(count));
    }
    if (options.backend != BackendKind::kCpu) {
#if LUCENT_HAVE_CUDA
        std::string why;
        if (auto backend =
                cuda::make_cuda_backend(0, &why, options.register_variants, options.tree_upgrades))
            return backend;
        if (options.backend == BackendKind::kCuda)
            throw Error("Context: the CUDA backend cannot run here: " + why +
                        "; use --backend cpu or --backend auto");
        notice = why + ": running on the CPU";
#else
        if (options.backend == BackendKind::kCuda)
            throw Error(
                "Context: the CUDA backend is not part of this build (it needs the CUDA toolkit "
                "at configure time); use --backend cpu or --backend auto");
        notice = "this build has no CUDA backend: running on the CPU";
#endif
    }
    return make_cpu_backend(options.threads);
}
}  // namespace

std::unique_ptr<Backend> make_backend(const ContextOptions& options, std::string& notice) {
    auto local = make_local_backend(options, notice);
    if (!options.ranks) return local;
    return make_distributed_backend(std::move(local), options.ranks);
}

int gpu_count() {
#if LUCENT_HAVE_CUDA
    return cuda::gpu_count();
#else
    return 0;
#endif
}

bool can_jit_check() {
#if LUCENT_HAVE_CUDA
    return true;
#else
    return false;
#endif
}

void jit_check(const CompiledScene& scene, int sm, LaunchReport& report) {
#if LUCENT_HAVE_CUDA
    cuda::Megakernel kernel = cuda::generate_megakernel(scene, cuda::build_program_table(scene));
    cuda::compile_megakernel(kernel, sm);
    report.jit_ms = kernel.jit_ms;
    report.jit_cached = kernel.from_cache;
#else
    (void)scene, (void)sm, (void)report;
    throw Error("Context: the JIT check needs a build with the CUDA toolkit; drop the option");
#endif
}

std::unique_ptr<GlTexture::Impl> make_gl_texture_interop(unsigned gl_texture) {
#if LUCENT_HAVE_CUDA
    return cuda::make_gl_texture_interop(gl_texture);
#else
    (void)gl_texture;
    throw Error("CUDA-OpenGL interop: this build of Lucent has no CUDA backend");
#endif
}

}  // namespace lucent::core

#include "cuda/interop/display_frame.h"

#include <algorithm>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "cuda/device/lucent_gpu/display.cuh"
#include "cuda/backend/driver_api.h"
#include "cuda/interop/scoped_context.h"
#include "cuda/jit/nvrtc_compiler.h"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {

const DriverApi& api() {
    return require_driver("display frames");
}

}  // namespace

/// Pixel blocks of one GPU, shared by its encoder and the frames it made. Holds a reference
/// to the GPU's primary context so the blocks stay valid after the Context is gone.
struct DisplayPool {
    static constexpr size_t kKept = 4;  // the viewer holds about three frames at once

    explicit DisplayPool(CUdevice device) : device(device) {
        check(api().cuDevicePrimaryCtxRetain(&context, device), "cuDevicePrimaryCtxRetain");
    }
    ~DisplayPool() {
        if (const DriverApi* d = driver()) {  // errors while tearing down are not actionable
            d->cuCtxPushCurrent(context);
            for (const auto& block : free) d->cuMemFree(block.second);
            if (module) d->cuModuleUnload(module);
            CUcontext popped = nullptr;
            d->cuCtxPopCurrent(&popped);
            d->cuDevicePrimaryCtxRelease(device);
        }
    }

    /// A block of `bytes`; the caller has this GPU's context current.
    CUdeviceptr take(size_t bytes) {
        {
            std::lock_guard lock(mutex);
            auto it = std::find_if(free.begin(), free.end(),
                                   [&](const auto& block) { return block.first == bytes; });
            if (it != free.end()) {
                const CUdeviceptr ptr = it->second;
                free.erase(it);
                return ptr;
            }
        }
        CUdeviceptr ptr = 0;
        check(api().cuMemAlloc(&ptr, bytes), "cuMemAlloc (display frame)");
        return ptr;
    }
    /// Called by a frame's destructor, on any thread.
    void give_back(CUdeviceptr ptr, size_t bytes) {
        std::lock_guard lock(mutex);
        free.emplace_back(bytes, ptr);
        if (free.size() > kKept) {
            ScopedContext scope(api(), context);
            api().cuMemFree(free.front().second);
            free.erase(free.begin());
        }
    }

    CUdevice device;
    CUcontext context = nullptr;
    CUmodule module = nullptr;  // lucent_gpu/display.cuh
    CUfunction encode = nullptr, to_surface = nullptr;
    std::mutex mutex;
    std::vector<std::pair<size_t, CUdeviceptr>> free;  // (bytes, block), oldest first
};

CudaDisplayFrame::CudaDisplayFrame(std::shared_ptr<DisplayPool> pool, CUdeviceptr pixels,
                                   unsigned width, unsigned height)
    : DisplayFrame(width, height), m_pool(std::move(pool)), m_pixels(pixels) {}

CudaDisplayFrame::~CudaDisplayFrame() {
    m_pool->give_back(m_pixels, bytes());
}

CUcontext CudaDisplayFrame::context() const {
    return m_pool->context;
}

void CudaDisplayFrame::copy_to_surface(CUsurfObject surface) const {
    CUdeviceptr pixels = m_pixels;
    unsigned width = this->width(), height = this->height();
    void* args[] = {&pixels, &surface, &width, &height};
    // No wait here: the unmap that follows on the same stream orders OpenGL after the kernel,
    // and the frame's block is only reused (or freed) behind it.
    check(api().cuLaunchKernel(m_pool->to_surface, (width + 31) / 32, (height + 7) / 8, 1, 32, 8, 1,
                               0, nullptr, args, nullptr),
          "copy a display frame into an OpenGL texture");
}

std::vector<unsigned char> CudaDisplayFrame::rgba() const {
    std::vector<unsigned char> pixels(bytes());
    ScopedContext scope(api(), m_pool->context);
    check(api().cuMemcpyDtoH(pixels.data(), m_pixels, pixels.size()), "download a display frame");
    return pixels;
}

DisplayEncoder::DisplayEncoder(CUdevice device, int sm)
    : m_pool(std::make_shared<DisplayPool>(device)) {
    const CompileResult compiled = compile_cubin(embedded_request(
        "lucent_display.cu", "#include \"lucent_gpu/display.cuh\"\n", {"--std=c++17"}, sm));
    check(api().cuModuleLoadData(&m_pool->module, compiled.cubin.data()),
          "cuModuleLoadData (display frames)");
    check(api().cuModuleGetFunction(&m_pool->encode, m_pool->module, "lucent_display_srgb8"),
          "lucent_display_srgb8");
    check(
        api().cuModuleGetFunction(&m_pool->to_surface, m_pool->module, "lucent_display_to_surface"),
        "lucent_display_to_surface");
    m_thresholds.upload(srgb8_thresholds(), gpu::kSrgbThresholds * sizeof(float));
}

std::shared_ptr<DisplayFrame> DisplayEncoder::encode(CUdeviceptr linear, unsigned width,
                                                     unsigned height) {
    unsigned count = width * height;
    CUdeviceptr pixels = m_pool->take(size_t(count) * 4);
    auto frame = std::make_shared<CudaDisplayFrame>(m_pool, pixels, width, height);
    CUdeviceptr thresholds = m_thresholds.ptr();
    void* args[] = {&linear, &pixels, &count, &thresholds};
    const unsigned blocks =
        std::min(4096u, (count + gpu::kDisplayThreads - 1) / gpu::kDisplayThreads);
    // The legacy default stream: it waits for the launch's (blocking) streams.
    check(api().cuLaunchKernel(m_pool->encode, std::max(blocks, 1u), 1, 1, gpu::kDisplayThreads, 1,
                               1, 0, nullptr, args, nullptr),
          "encode a display frame");
    check(api().cuStreamSynchronize(nullptr), "encode a display frame");
    return frame;
}

}  // namespace lucent::cuda

#include "cuda/display_frame.h"

#include <algorithm>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "cuda/device/lucent_gpu/display.cuh"
#include "cuda/driver_api.h"
#include "cuda/nvrtc_compiler.h"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {

const DriverApi& api() {
    return require_driver("display frames");
}

/// Makes `context` current on this thread for the scope, restoring the previous one (frames
/// and GlTexture are used from the application's threads, e.g. its OpenGL thread).
class ScopedContext {
  public:
    explicit ScopedContext(CUcontext context) {
        check(api().cuCtxPushCurrent(context), "cuCtxPushCurrent");
    }
    ~ScopedContext() {
        CUcontext popped = nullptr;
        api().cuCtxPopCurrent(&popped);
    }
    ScopedContext(const ScopedContext&) = delete;
    ScopedContext& operator=(const ScopedContext&) = delete;
};

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
            ScopedContext scope(context);
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
    ScopedContext scope(m_pool->context);
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

// ---- GlTexture (lucent/display.h): CUDA–OpenGL interop --------------------------------

}  // namespace lucent::cuda

namespace lucent {

namespace {
constexpr unsigned kGlTexture2D = 0x0DE1;  // GL_TEXTURE_2D (no OpenGL headers here)
}

struct GlTexture::Impl {
    const cuda::DriverApi* d = nullptr;
    CUgraphicsResource resource = nullptr;
    CUcontext context = nullptr;  // the GPU it is registered with
    CUarray array = nullptr;      // the texture's array when last mapped,
    CUsurfObject surface = 0;     // and a surface over it (kept while the array stays)

    /// A surface over `mapped`, made again when the mapping gives another array.
    CUsurfObject surface_for(CUarray mapped) {
        if (mapped == array && surface) return surface;
        drop_surface();
        CUDA_RESOURCE_DESC resource_desc{};
        resource_desc.resType = CU_RESOURCE_TYPE_ARRAY;
        resource_desc.res.array.hArray = mapped;
        cuda::check(d->cuSurfObjectCreate(&surface, &resource_desc), "cuSurfObjectCreate");
        array = mapped;
        return surface;
    }
    void drop_surface() {
        if (!surface) return;
        d->cuStreamSynchronize(nullptr);  // no queued copy uses it any more
        d->cuSurfObjectDestroy(surface);
        surface = 0;
        array = nullptr;
    }
};

GlTexture::GlTexture(unsigned gl_texture) : m_gl_texture(gl_texture), m(std::make_unique<Impl>()) {
    std::string why;
    m->d = cuda::driver(&why);
    if (!m->d) throw Error("CUDA-OpenGL interop: " + why);
}

GlTexture::~GlTexture() {
    release();
}

void GlTexture::release() {
    if (!m->resource) return;
    m->d->cuCtxPushCurrent(m->context);
    m->drop_surface();
    m->d->cuGraphicsUnregisterResource(m->resource);  // errors while tearing down: nothing to do
    CUcontext popped = nullptr;
    m->d->cuCtxPopCurrent(&popped);
    m->resource = nullptr;
    m->context = nullptr;
}

void GlTexture::copy_from(const DisplayFrame& frame) {
    const auto* device_frame = dynamic_cast<const cuda::CudaDisplayFrame*>(&frame);
    if (!device_frame)
        throw Error(
            "GlTexture::copy_from: the frame is in host memory; upload its rgba() to "
            "OpenGL instead");
    if (m->resource && m->context != device_frame->context()) release();  // another GPU
    cuda::ScopedContext scope(device_frame->context());
    const cuda::DriverApi& d = *m->d;
    if (!m->resource) {
        const CUresult r = d.cuGraphicsGLRegisterImage(&m->resource, m_gl_texture, kGlTexture2D,
                                                       CU_GRAPHICS_REGISTER_FLAGS_WRITE_DISCARD);
        if (r != CUDA_SUCCESS) {
            m->resource = nullptr;
            const char* s = nullptr;
            d.cuGetErrorString(r, &s);
            throw Error("CUDA-OpenGL interop: cannot register OpenGL texture " +
                        std::to_string(m_gl_texture) + " with the GPU (" + (s ? s : "?") +
                        "); the OpenGL context must be current and run on the same NVIDIA GPU");
        }
        m->context = device_frame->context();
    }
    cuda::check(d.cuGraphicsMapResources(1, &m->resource, nullptr), "cuGraphicsMapResources");
    CUarray array = nullptr;
    CUresult r = d.cuGraphicsSubResourceGetMappedArray(&array, m->resource, 0, 0);
    CUDA_ARRAY_DESCRIPTOR shape{};
    if (r == CUDA_SUCCESS) r = d.cuArrayGetDescriptor(&shape, array);
    const bool fits = r == CUDA_SUCCESS && shape.Width == frame.width() &&
                      shape.Height == frame.height() && shape.NumChannels == 4 &&
                      shape.Format == CU_AD_FORMAT_UNSIGNED_INT8;
    std::string failure;
    if (fits) {
        try {
            device_frame->copy_to_surface(m->surface_for(array));
        } catch (const Error& e) {
            failure = e.what();
        }
    }
    d.cuGraphicsUnmapResources(1, &m->resource, nullptr);
    cuda::check(r, "map an OpenGL texture for CUDA");
    if (!failure.empty()) throw Error(failure);
    if (!fits)
        throw Error("GlTexture::copy_from: OpenGL texture " + std::to_string(m_gl_texture) +
                    " is " + std::to_string(shape.Width) + "x" + std::to_string(shape.Height) +
                    (shape.NumChannels == 4 ? "" : " and not RGBA8") + " but the frame is " +
                    std::to_string(frame.width()) + "x" + std::to_string(frame.height()) +
                    "; release() it, glTexImage2D it as GL_RGBA8 of the frame's size, then "
                    "copy again");
}

}  // namespace lucent

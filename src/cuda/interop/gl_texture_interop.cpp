#include "cuda/interop/gl_texture_interop.h"

#include <string>

#include "cuda/backend/driver_api.h"
#include "cuda/interop/display_frame.h"
#include "cuda/interop/scoped_context.h"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {

constexpr unsigned kGlTexture2D = 0x0DE1;  // GL_TEXTURE_2D (no OpenGL headers here)

class CudaGlTexture final : public GlTexture::Impl {
  public:
    explicit CudaGlTexture(unsigned gl_texture) : m_gl_texture(gl_texture) {
        std::string why;
        d = driver(&why);
        if (!d) throw Error("CUDA-OpenGL interop: " + why);
    }
    ~CudaGlTexture() override { release(); }

    void release() override {
        if (!resource) return;
        d->cuCtxPushCurrent(context);
        drop_surface();
        d->cuGraphicsUnregisterResource(resource);  // errors while tearing down: nothing to do
        CUcontext popped = nullptr;
        d->cuCtxPopCurrent(&popped);
        resource = nullptr;
        context = nullptr;
    }

    void copy_from(const DisplayFrame& frame) override;

  private:
    /// A surface over `mapped`, made again when the mapping gives another array.
    CUsurfObject surface_for(CUarray mapped) {
        if (mapped == array && surface) return surface;
        drop_surface();
        CUDA_RESOURCE_DESC resource_desc{};
        resource_desc.resType = CU_RESOURCE_TYPE_ARRAY;
        resource_desc.res.array.hArray = mapped;
        check(d->cuSurfObjectCreate(&surface, &resource_desc), "cuSurfObjectCreate");
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

    unsigned m_gl_texture;
    const DriverApi* d = nullptr;
    CUgraphicsResource resource = nullptr;
    CUcontext context = nullptr;  // the GPU it is registered with
    CUarray array = nullptr;      // the texture's array when last mapped,
    CUsurfObject surface = 0;     // and a surface over it (kept while the array stays)
};

void CudaGlTexture::copy_from(const DisplayFrame& frame) {
    const auto* device_frame = dynamic_cast<const CudaDisplayFrame*>(&frame);
    if (!device_frame)
        throw Error(
            "GlTexture::copy_from: the frame is in host memory; upload its rgba() to "
            "OpenGL instead");
    if (resource && context != device_frame->context()) release();  // another GPU
    ScopedContext scope(*d, device_frame->context());
    const DriverApi& api = *d;
    if (!resource) {
        const CUresult r = api.cuGraphicsGLRegisterImage(&resource, m_gl_texture, kGlTexture2D,
                                                         CU_GRAPHICS_REGISTER_FLAGS_WRITE_DISCARD);
        if (r != CUDA_SUCCESS) {
            resource = nullptr;
            const char* s = nullptr;
            api.cuGetErrorString(r, &s);
            throw Error("CUDA-OpenGL interop: cannot register OpenGL texture " +
                        std::to_string(m_gl_texture) + " with the GPU (" + (s ? s : "?") +
                        "); the OpenGL context must be current and run on the same NVIDIA GPU");
        }
        context = device_frame->context();
    }
    check(api.cuGraphicsMapResources(1, &resource, nullptr), "cuGraphicsMapResources");
    CUarray mapped = nullptr;
    CUresult r = api.cuGraphicsSubResourceGetMappedArray(&mapped, resource, 0, 0);
    CUDA_ARRAY_DESCRIPTOR shape{};
    if (r == CUDA_SUCCESS) r = api.cuArrayGetDescriptor(&shape, mapped);
    const bool fits = r == CUDA_SUCCESS && shape.Width == frame.width() &&
                      shape.Height == frame.height() && shape.NumChannels == 4 &&
                      shape.Format == CU_AD_FORMAT_UNSIGNED_INT8;
    std::string failure;
    if (fits) {
        try {
            device_frame->copy_to_surface(surface_for(mapped));
        } catch (const Error& e) {
            failure = e.what();
        }
    }
    api.cuGraphicsUnmapResources(1, &resource, nullptr);
    check(r, "map an OpenGL texture for CUDA");
    if (!failure.empty()) throw Error(failure);
    if (!fits)
        throw Error("GlTexture::copy_from: OpenGL texture " + std::to_string(m_gl_texture) +
                    " is " + std::to_string(shape.Width) + "x" + std::to_string(shape.Height) +
                    (shape.NumChannels == 4 ? "" : " and not RGBA8") + " but the frame is " +
                    std::to_string(frame.width()) + "x" + std::to_string(frame.height()) +
                    "; release() it, glTexImage2D it as GL_RGBA8 of the frame's size, then "
                    "copy again");
}

}  // namespace

std::unique_ptr<GlTexture::Impl> make_gl_texture_interop(unsigned gl_texture) {
    return std::make_unique<CudaGlTexture>(gl_texture);
}

}  // namespace lucent::cuda

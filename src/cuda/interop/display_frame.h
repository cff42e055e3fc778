// Display frames on a GPU (Context::display_frame on the CUDA backend): the launch's float4
// output encoded as RGBA8 in device memory, and handed to OpenGL by GlTexture
// (lucent/display.h) without a trip through host memory.
#pragma once

#include <cuda.h>

#include <memory>

#include "cuda/backend/device_buffer.h"
#include "lucent/display.h"

namespace lucent::cuda {

struct DisplayPool;

/// A frame's RGBA8 pixels in device memory. Keeps the GPU's primary context alive, so it
/// may outlive the Context that made it and be shown from another thread.
class CudaDisplayFrame final : public DisplayFrame {
  public:
    CudaDisplayFrame(std::shared_ptr<DisplayPool> pool, CUdeviceptr pixels, unsigned width,
                     unsigned height);
    ~CudaDisplayFrame() override;
    bool on_device() const override { return true; }
    std::vector<unsigned char> rgba() const override;
    CUdeviceptr pixels() const { return m_pixels; }
    CUcontext context() const;
    /// Queues, on the legacy default stream with this frame's context current, a kernel that
    /// writes the pixels through `surface` (over an array of the frame's size: an OpenGL
    /// texture's, mapped by GlTexture).
    void copy_to_surface(CUsurfObject surface) const;

  private:
    std::shared_ptr<DisplayPool> m_pool;
    CUdeviceptr m_pixels;
};

/// Encodes device float4 images into display frames on one GPU (an NVRTC kernel,
/// lucent_gpu/display.cuh). Pixel blocks of freed frames are reused.
class DisplayEncoder {
  public:
    /// For `device` (compute capability `sm`, x10); its primary context must be current.
    DisplayEncoder(CUdevice device, int sm);
    DisplayEncoder(const DisplayEncoder&) = delete;
    DisplayEncoder& operator=(const DisplayEncoder&) = delete;

    /// Encodes width x height float4 pixels at `linear` after the work queued before it on
    /// the current context, and returns when the frame is complete.
    std::shared_ptr<DisplayFrame> encode(CUdeviceptr linear, unsigned width, unsigned height);

  private:
    std::shared_ptr<DisplayPool> m_pool;  // also holds the kernels
    DeviceBuffer m_thresholds;
};

}  // namespace lucent::cuda

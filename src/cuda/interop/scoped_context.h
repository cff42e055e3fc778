// A CUDA context made current for a scope, on any thread.
#pragma once

#include <cuda.h>

#include "cuda/backend/driver_api.h"

namespace lucent::cuda {

/// Makes `context` current on this thread for the scope, restoring the previous one (frames
/// and GlTexture are used from the application's threads, e.g. its OpenGL thread).
class ScopedContext {
  public:
    ScopedContext(const DriverApi& api, CUcontext context) : m_api(api) {
        check(api.cuCtxPushCurrent(context), "cuCtxPushCurrent");
    }
    ~ScopedContext() {
        CUcontext popped = nullptr;
        m_api.cuCtxPopCurrent(&popped);
    }
    ScopedContext(const ScopedContext&) = delete;
    ScopedContext& operator=(const ScopedContext&) = delete;

  private:
    const DriverApi& m_api;
};

}  // namespace lucent::cuda

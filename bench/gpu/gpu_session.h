// The GPU plumbing of the benchmarks that drive kernels themselves (bench rays and bench
// build --backend cuda): device 0's primary context, a loaded module, CUDA events.
#pragma once

#include <cuda.h>

#include <string>

#include "cuda/backend/driver_api.h"

namespace lucent::cuda {

/// The driver, or lucent::Error telling the user to run with --backend cpu.
const DriverApi& require_bench_driver();

/// The primary context of device 0, current while this object lives.
class ContextScope {
  public:
    explicit ContextScope(const DriverApi& api) : m_api(api) {
        check(api.cuDeviceGet(&m_device, 0), "cuDeviceGet");
        check(api.cuDevicePrimaryCtxRetain(&m_context, m_device), "cuDevicePrimaryCtxRetain");
        check(api.cuCtxSetCurrent(m_context), "cuCtxSetCurrent");
    }
    ~ContextScope() { m_api.cuDevicePrimaryCtxRelease(m_device); }
    ContextScope(const ContextScope&) = delete;
    ContextScope& operator=(const ContextScope&) = delete;

    CUdevice device() const { return m_device; }
    int attribute(CUdevice_attribute a) const {
        int v = 0;
        check(m_api.cuDeviceGetAttribute(&v, a, m_device), "cuDeviceGetAttribute");
        return v;
    }
    /// Compute capability x10 (90 for sm_90).
    int sm() const {
        return 10 * attribute(CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MAJOR) +
               attribute(CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MINOR);
    }
    std::string name() const {
        char buf[256] = {};
        check(m_api.cuDeviceGetName(buf, sizeof buf, m_device), "cuDeviceGetName");
        return buf;
    }

  private:
    const DriverApi& m_api;
    CUdevice m_device = 0;
    CUcontext m_context = nullptr;
};

class Module {
  public:
    Module(const DriverApi& api, const std::string& cubin) : m_api(api) {
        check(api.cuModuleLoadData(&m_module, cubin.data()), "cuModuleLoadData");
    }
    ~Module() { m_api.cuModuleUnload(m_module); }
    Module(const Module&) = delete;
    Module& operator=(const Module&) = delete;
    CUfunction function(const char* name) const {
        CUfunction f = nullptr;
        check(m_api.cuModuleGetFunction(&f, m_module, name), name);
        return f;
    }

  private:
    const DriverApi& m_api;
    CUmodule m_module = nullptr;
};

class Event {
  public:
    explicit Event(const DriverApi& api) : m_api(api) {
        check(api.cuEventCreate(&m_event, CU_EVENT_DEFAULT), "cuEventCreate");
    }
    ~Event() { m_api.cuEventDestroy(m_event); }
    Event(const Event&) = delete;
    Event& operator=(const Event&) = delete;
    CUevent get() const { return m_event; }

  private:
    const DriverApi& m_api;
    CUevent m_event = nullptr;
};

}  // namespace lucent::cuda

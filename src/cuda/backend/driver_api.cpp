#include "cuda/backend/driver_api.h"

#include <dlfcn.h>

#include <mutex>

#include "lucent/error.h"

namespace lucent::cuda {

namespace {
struct Loaded {
    DriverApi api;
    bool ok = false;
    std::string why;
};

Loaded load() {
    Loaded l;
    void* lib = dlopen("libcuda.so.1", RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        l.why = "no NVIDIA driver (libcuda.so.1 not found)";
        return l;
    }
    bool missing = false;
    // cuXxx_v2 entry points are what the unversioned names in cuda.h map to.
    auto get = [&](auto& fn, const char* name) {
        void* sym = dlsym(lib, name);
        if (!sym) {
            l.why = std::string("the NVIDIA driver lacks ") + name;
            missing = true;
        }
        fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(sym);
    };
#define LUCENT_LOAD(field, symbol) get(l.api.field, symbol);
    LUCENT_LOAD(cuInit, "cuInit")
    LUCENT_LOAD(cuDriverGetVersion, "cuDriverGetVersion")
    LUCENT_LOAD(cuDeviceGetCount, "cuDeviceGetCount")
    LUCENT_LOAD(cuDeviceGet, "cuDeviceGet")
    LUCENT_LOAD(cuDeviceGetName, "cuDeviceGetName")
    LUCENT_LOAD(cuDeviceGetAttribute, "cuDeviceGetAttribute")
    LUCENT_LOAD(cuDevicePrimaryCtxRetain, "cuDevicePrimaryCtxRetain")
    LUCENT_LOAD(cuDevicePrimaryCtxRelease, "cuDevicePrimaryCtxRelease_v2")
    LUCENT_LOAD(cuCtxSetCurrent, "cuCtxSetCurrent")
    LUCENT_LOAD(cuCtxSynchronize, "cuCtxSynchronize")
    LUCENT_LOAD(cuCtxSetLimit, "cuCtxSetLimit")
    LUCENT_LOAD(cuModuleLoadData, "cuModuleLoadData")
    LUCENT_LOAD(cuModuleUnload, "cuModuleUnload")
    LUCENT_LOAD(cuModuleGetFunction, "cuModuleGetFunction")
    LUCENT_LOAD(cuModuleGetGlobal, "cuModuleGetGlobal_v2")
    LUCENT_LOAD(cuLaunchKernel, "cuLaunchKernel")
    LUCENT_LOAD(cuMemAlloc, "cuMemAlloc_v2")
    LUCENT_LOAD(cuMemFree, "cuMemFree_v2")
    LUCENT_LOAD(cuMemcpyHtoD, "cuMemcpyHtoD_v2")
    LUCENT_LOAD(cuMemcpyDtoH, "cuMemcpyDtoH_v2")
    LUCENT_LOAD(cuMemsetD8, "cuMemsetD8_v2")
    LUCENT_LOAD(cuMemAllocHost, "cuMemAllocHost_v2")
    LUCENT_LOAD(cuMemFreeHost, "cuMemFreeHost")
    LUCENT_LOAD(cuMemcpyDtoHAsync, "cuMemcpyDtoHAsync_v2")
    LUCENT_LOAD(cuMemcpyHtoDAsync, "cuMemcpyHtoDAsync_v2")
    LUCENT_LOAD(cuMemcpyDtoDAsync, "cuMemcpyDtoDAsync_v2")
    LUCENT_LOAD(cuEventCreate, "cuEventCreate")
    LUCENT_LOAD(cuEventDestroy, "cuEventDestroy_v2")
    LUCENT_LOAD(cuEventRecord, "cuEventRecord")
    LUCENT_LOAD(cuEventSynchronize, "cuEventSynchronize")
    LUCENT_LOAD(cuEventElapsedTime, "cuEventElapsedTime")
    LUCENT_LOAD(cuGetErrorString, "cuGetErrorString")
    LUCENT_LOAD(cuFuncGetAttribute, "cuFuncGetAttribute")
    LUCENT_LOAD(cuFuncSetAttribute, "cuFuncSetAttribute")
    LUCENT_LOAD(cuOccupancyMaxActiveBlocksPerMultiprocessor,
                "cuOccupancyMaxActiveBlocksPerMultiprocessor")
    LUCENT_LOAD(cuStreamCreate, "cuStreamCreate")
    LUCENT_LOAD(cuStreamDestroy, "cuStreamDestroy_v2")
    LUCENT_LOAD(cuStreamSynchronize, "cuStreamSynchronize")
    LUCENT_LOAD(cuStreamWaitEvent, "cuStreamWaitEvent")
    LUCENT_LOAD(cuMemsetD32Async, "cuMemsetD32Async")
    LUCENT_LOAD(cuMemcpyPeer, "cuMemcpyPeer")
    LUCENT_LOAD(cuDeviceCanAccessPeer, "cuDeviceCanAccessPeer")
    LUCENT_LOAD(cuCtxEnablePeerAccess, "cuCtxEnablePeerAccess")
    LUCENT_LOAD(cuDeviceGetP2PAttribute, "cuDeviceGetP2PAttribute")
    LUCENT_LOAD(cuArrayGetDescriptor, "cuArrayGetDescriptor_v2")
    LUCENT_LOAD(cuSurfObjectCreate, "cuSurfObjectCreate")
    LUCENT_LOAD(cuSurfObjectDestroy, "cuSurfObjectDestroy")
    LUCENT_LOAD(cuCtxPushCurrent, "cuCtxPushCurrent_v2")
    LUCENT_LOAD(cuCtxPopCurrent, "cuCtxPopCurrent_v2")
    LUCENT_LOAD(cuGraphicsUnregisterResource, "cuGraphicsUnregisterResource")
    LUCENT_LOAD(cuGraphicsMapResources, "cuGraphicsMapResources")
    LUCENT_LOAD(cuGraphicsUnmapResources, "cuGraphicsUnmapResources")
    LUCENT_LOAD(cuGraphicsSubResourceGetMappedArray, "cuGraphicsSubResourceGetMappedArray")
    LUCENT_LOAD(cuGraphicsGLRegisterImage, "cuGraphicsGLRegisterImage")
#undef LUCENT_LOAD
    if (missing) return l;
    if (CUresult r = l.api.cuInit(0); r != CUDA_SUCCESS) {
        const char* s = nullptr;
        l.api.cuGetErrorString(r, &s);
        l.why = std::string("the NVIDIA driver did not initialise: ") + (s ? s : "unknown error");
        return l;
    }
    int count = 0;
    if (l.api.cuDeviceGetCount(&count) != CUDA_SUCCESS || count == 0) {
        l.why = "the NVIDIA driver reports no GPU";
        return l;
    }
    l.ok = true;
    return l;
}
}  // namespace

const DriverApi* driver(std::string* why) {
    static const Loaded loaded = load();
    if (!loaded.ok && why) *why = loaded.why;
    return loaded.ok ? &loaded.api : nullptr;
}

const DriverApi& require_driver(const char* what) {
    std::string why;
    const DriverApi* d = driver(&why);
    if (!d) throw Error(std::string(what) + ": " + why);
    return *d;
}

void check(CUresult result, const char* what) {
    if (result == CUDA_SUCCESS) return;
    const char* s = nullptr;
    if (const DriverApi* d = driver()) d->cuGetErrorString(result, &s);
    throw Error(std::string("CUDA: ") + what + ": " +
                (s ? s : "error " + std::to_string(int(result))));
}

}  // namespace lucent::cuda

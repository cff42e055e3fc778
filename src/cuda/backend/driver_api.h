// The CUDA driver API, loaded at run time (dlopen of libcuda.so.1), so the `lucent` binary
// starts on machines without an NVIDIA driver and `--backend auto` can fall back to the CPU.
#pragma once

#include <cuda.h>

#include <string>

namespace lucent::cuda {

struct DriverApi {
#define LUCENT_CU_FN(name) decltype(&::name) name = nullptr;
    LUCENT_CU_FN(cuInit)
    LUCENT_CU_FN(cuDriverGetVersion)
    LUCENT_CU_FN(cuDeviceGetCount)
    LUCENT_CU_FN(cuDeviceGet)
    LUCENT_CU_FN(cuDeviceGetName)
    LUCENT_CU_FN(cuDeviceGetAttribute)
    LUCENT_CU_FN(cuDevicePrimaryCtxRetain)
    LUCENT_CU_FN(cuDevicePrimaryCtxRelease)
    LUCENT_CU_FN(cuCtxSetCurrent)
    LUCENT_CU_FN(cuCtxSynchronize)
    LUCENT_CU_FN(cuCtxSetLimit)
    LUCENT_CU_FN(cuModuleLoadData)
    LUCENT_CU_FN(cuModuleUnload)
    LUCENT_CU_FN(cuModuleGetFunction)
    LUCENT_CU_FN(cuModuleGetGlobal)
    LUCENT_CU_FN(cuLaunchKernel)
    LUCENT_CU_FN(cuMemAlloc)
    LUCENT_CU_FN(cuMemFree)
    LUCENT_CU_FN(cuMemcpyHtoD)
    LUCENT_CU_FN(cuMemcpyDtoH)
    LUCENT_CU_FN(cuMemsetD8)
    LUCENT_CU_FN(cuMemAllocHost)
    LUCENT_CU_FN(cuMemFreeHost)
    LUCENT_CU_FN(cuMemcpyDtoHAsync)
    LUCENT_CU_FN(cuMemcpyHtoDAsync)
    LUCENT_CU_FN(cuMemcpyDtoDAsync)
    LUCENT_CU_FN(cuEventCreate)
    LUCENT_CU_FN(cuEventDestroy)
    LUCENT_CU_FN(cuEventRecord)
    LUCENT_CU_FN(cuEventSynchronize)
    LUCENT_CU_FN(cuEventElapsedTime)
    LUCENT_CU_FN(cuGetErrorString)
    LUCENT_CU_FN(cuFuncGetAttribute)
    LUCENT_CU_FN(cuFuncSetAttribute)
    LUCENT_CU_FN(cuOccupancyMaxActiveBlocksPerMultiprocessor)
    LUCENT_CU_FN(cuStreamCreate)
    LUCENT_CU_FN(cuStreamDestroy)
    LUCENT_CU_FN(cuStreamSynchronize)
    LUCENT_CU_FN(cuStreamWaitEvent)
    LUCENT_CU_FN(cuMemsetD32Async)
    LUCENT_CU_FN(cuMemcpyPeer)
    LUCENT_CU_FN(cuDeviceCanAccessPeer)
    LUCENT_CU_FN(cuCtxEnablePeerAccess)
    LUCENT_CU_FN(cuDeviceGetP2PAttribute)
    LUCENT_CU_FN(cuArrayGetDescriptor)
    LUCENT_CU_FN(cuSurfObjectCreate)
    LUCENT_CU_FN(cuSurfObjectDestroy)
    LUCENT_CU_FN(cuCtxPushCurrent)
    LUCENT_CU_FN(cuCtxPopCurrent)
    LUCENT_CU_FN(cuGraphicsUnregisterResource)
    LUCENT_CU_FN(cuGraphicsMapResources)
    LUCENT_CU_FN(cuGraphicsUnmapResources)
    LUCENT_CU_FN(cuGraphicsSubResourceGetMappedArray)
#undef LUCENT_CU_FN
    /// cudaGL.h's, declared here so the engine needs no OpenGL headers (GLuint and GLenum
    /// are unsigned ints).
    CUresult (*cuGraphicsGLRegisterImage)(CUgraphicsResource*, unsigned int gl_image,
                                          unsigned int gl_target, unsigned int flags) = nullptr;
};

/// The driver, loaded and initialised once; null when there is none (`why` says what failed).
const DriverApi* driver(std::string* why = nullptr);

/// The driver, or lucent::Error "<what>: <why there is none>".
const DriverApi& require_driver(const char* what);

/// Throws lucent::Error "<what>: <CUDA error string>" when result is not CUDA_SUCCESS.
void check(CUresult result, const char* what);

}  // namespace lucent::cuda

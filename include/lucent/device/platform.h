// Compiler detection for code that is compiled by g++, nvcc and NVRTC alike
// (pbrt-v4's PBRT_CPU_GPU pattern).
#pragma once

#if defined(__CUDACC__) || defined(__CUDACC_RTC__)
#define LUCENT_HD __host__ __device__
#define LUCENT_CUDA_TYPES 1
#else
#define LUCENT_HD
#define LUCENT_CUDA_TYPES 0
#endif

// True while compiling code that runs on the GPU (nvcc device pass or NVRTC).
#if defined(__CUDA_ARCH__) || defined(__CUDACC_RTC__)
#define LUCENT_GPU_CODE 1
#else
#define LUCENT_GPU_CODE 0
#endif

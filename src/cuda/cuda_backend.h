// Factory of the CUDA backend (built when the CUDA toolkit is found).
#pragma once

#include <memory>
#include <string>

#include "core/backend.h"

namespace lucent::cuda {

/// The CUDA backend on GPU 0, or null (with the reason in `why`) when no driver, GPU or
/// NVRTC answers.
std::unique_ptr<core::Backend> make_cuda_backend(std::string* why);

}  // namespace lucent::cuda

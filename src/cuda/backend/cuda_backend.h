// Factory of the CUDA backend (built when the CUDA toolkit is found).
#pragma once

#include <memory>
#include <string>

#include "core/backend.h"
#include "lucent/context.h"

namespace lucent::cuda {

/// The CUDA backend on GPU `ordinal`, or null (with the reason in `why`) when no driver,
/// such GPU or NVRTC answers.
std::unique_ptr<core::Backend> make_cuda_backend(
    int ordinal, std::string* why,
    RegisterVariants register_variants = RegisterVariants::kBackground,
    TreeUpgrades tree_upgrades = TreeUpgrades::kBackground);

/// GPUs the driver reports (0 without a driver).
int gpu_count();

}  // namespace lucent::cuda

// The one place that knows the backends (src/cpu, src/cuda). The core asks it for the
// Backend a Context runs on, for the GPUs there are, for a JIT check of a compiled scene
// (NVRTC without a GPU) and for CUDA–OpenGL interop; a build without the CUDA toolkit gets
// the CPU backend and clear errors for the rest.
#pragma once

#include <memory>
#include <string>

#include "core/backend.h"
#include "lucent/context.h"
#include "lucent/display.h"

namespace lucent::core {

/// The backend a Context with these options runs on: a multi-device backend over
/// options.devices when they are listed, else the backend options.backend names (kAuto:
/// the CUDA backend when it can run, else the CPU, with the reason in `notice`); with
/// options.ranks, that backend is this rank's part of a distributed one. Throws
/// lucent::Error naming the device or backend that cannot run and what to use instead.
std::unique_ptr<Backend> make_backend(const ContextOptions& options, std::string& notice);

/// GPUs the CUDA backend can see (0 in a build without it, or without a driver).
int gpu_count();

/// Whether this build can JIT-check megakernels (it has the CUDA backend's compiler).
bool can_jit_check();

/// Generates the megakernel of `scene` and compiles it with NVRTC for compute capability
/// `sm` (x10), no GPU needed; fills report.jit_ms and report.jit_cached. Throws
/// lucent::Error with NVRTC's log when it does not compile.
void jit_check(const CompiledScene& scene, int sm, LaunchReport& report);

/// What GlTexture copies device frames with (CUDA–OpenGL interop). Throws lucent::Error
/// when this build or machine cannot do it (no CUDA backend, no driver).
std::unique_ptr<GlTexture::Impl> make_gl_texture_interop(unsigned gl_texture);

}  // namespace lucent::core

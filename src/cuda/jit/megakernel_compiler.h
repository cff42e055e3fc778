// From a compiled scene to a CUBIN: program ids, kernel shape, generated source, NVRTC
// (through the disk cache). Needs no GPU, so CI checks that every sample's megakernel
// compiles (`lucent render --jit-check sm_90`).
#pragma once

#include "core/compiled_scene.h"
#include "cuda/jit/megakernel_generator.h"
#include "cuda/jit/nvrtc_compiler.h"

namespace lucent::cuda {

/// Ids for every program the scene binds, in a fixed walk of the scene.
ProgramTable build_program_table(const core::CompiledScene& scene);

struct Megakernel {
    std::string source;
    KernelShape shape;
    ModuleSourceList modules;  // the bound programs' module texts, headers of `source`
    CompileResult binary;
};

/// Generates the megakernel source of `scene` (binary left empty).
Megakernel generate_megakernel(const core::CompiledScene& scene, const ProgramTable& table);
/// Compiles it for compute capability `sm` (e.g. 90) through the disk cache.
void compile_megakernel(Megakernel& kernel, int sm);

}  // namespace lucent::cuda

// From a compiled scene to a CUBIN: program ids, kernel shape, generated source, NVRTC
// (through the disk cache). Needs no GPU, so CI checks that every sample's megakernel
// compiles (`lucent render --jit-check sm_90`).
#pragma once

#include <string>
#include <vector>

#include "core/compiled_scene.h"
#include "cuda/jit/megakernel_generator.h"
#include "cuda/jit/nvrtc_compiler.h"

namespace lucent::cuda {

/// Ids for every program the scene binds, in a fixed walk of the scene.
ProgramTable build_program_table(const core::CompiledScene& scene);

/// A scene's megakernel: one kernel per ray-generation program, each compiled as its own
/// unit (the common source and that kernel's definition) into its own module, so the units
/// compile in parallel and each kernel's code holds only what its program reaches.
struct Megakernel {
    std::string source;                // common to every unit
    std::vector<std::string> kernels;  // per ray-generation program: its kernel's definition
    KernelShape shape;
    ModuleSourceList modules;  // the bound programs' module texts, headers of `source`
    std::vector<CompileResult> binaries;  // per kernel, after compile_megakernel
    double jit_ms = 0;                    // the whole compile (or cache loads), wall time
    bool from_cache = false;              // every unit came from the kernel cache

    /// Everything that decides the binaries' code: whether a recompile is needed.
    std::string text() const;
};

/// Generates the megakernel source of `scene` (binaries left empty).
Megakernel generate_megakernel(const core::CompiledScene& scene, const ProgramTable& table);
/// Compiles its units for compute capability `sm` (e.g. 90) through the disk cache, on up to
/// one thread per unit and processor (8 at most); throws the first unit's error.
void compile_megakernel(Megakernel& kernel, int sm);

/// The NVRTC requests of the units of `kernels` (indices into kernel.kernels) for `sm`, with
/// `extra_options` after the usual ones (e.g. a register cap for a variant).
std::vector<CompileRequest> unit_requests(const Megakernel& kernel, int sm,
                                          const std::vector<size_t>& kernels,
                                          const std::vector<std::string>& extra_options);
/// Can the kernel compiled to `binary` be compiled again with trace() inlined into its
/// ray-generation program (-DLUCENT_GPU_INLINE_TRACE=1)? Where it calls trace_ray and
/// trace_ray never reaches itself (no closest-hit, any-hit, miss, intersection or callable
/// program that a trace runs traces again). Inlined, the trace's frame, ray and payload stay
/// in registers and the call's saves are gone (ptxas: bench rays' closest-hit kernel 92 ->
/// 72 registers, the direct sample's 149 -> 125); where the trace recurses, inlining would
/// unroll the recursion (35-114 s compiles of 255-register code). An unknown call graph (a
/// cache entry older than call graphs) says no.
bool can_inline_trace(const CompileResult& binary);

/// Compiles `requests` through the disk cache, side by side on up to one thread per request
/// and processor (8 at most); throws the first one's error.
std::vector<CompileResult> compile_units(const std::vector<CompileRequest>& requests);

}  // namespace lucent::cuda

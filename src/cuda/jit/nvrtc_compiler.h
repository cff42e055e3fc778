// Run-time compilation of CUDA C++ to a CUBIN with NVRTC (loaded at run time), behind a
// disk cache keyed on everything that decides the output (HIPRT's impl/Compiler.cpp idea).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "cuda/jit/ptx_calls.h"

namespace lucent::cuda {

struct CompileRequest {
    std::string name;  // e.g. "megakernel.cu"
    std::string source;
    std::vector<std::pair<std::string, std::string>> headers;  // include name → text
    std::vector<std::string> options;                          // besides the architecture
    int sm = 90;                                               // compute capability * 10
};

struct CompileResult {
    std::string cubin;
    bool from_cache = false;
    double ms = 0;    // compile (cold) or cache load time
    std::string log;  // NVRTC's log, even on success
    // Which functions of the compiled code call which (ptx_calls.h), kept beside the cached
    // CUBIN; not known for an entry cached before call graphs were.
    bool call_graph_known = false;
    PtxCallGraph call_graph;
};

/// A request for `source`, which may include any of Lucent's embedded device headers
/// (embedded_sources.h).
CompileRequest embedded_request(std::string name, std::string source,
                                std::vector<std::string> options, int sm);

/// Appends the whitespace-separated words of environment variable `variable`, when set, to
/// the request's options (tuning experiments: e.g. "-DLUCENT_GPU_MIN_BLOCKS=8").
void add_options_from_env(CompileRequest& request, const char* variable);

/// Compiles (or loads from the cache) a CUBIN. Throws lucent::Error with NVRTC's log on
/// failure. Cache directory: $LUCENT_CACHE_DIR, else $XDG_CACHE_HOME/lucent, else
/// ~/.cache/lucent; LUCENT_CACHE_DIR=off disables it.
CompileResult compile_cubin(const CompileRequest& request);

/// NVRTC's version as "13.0", or an empty string (with `why`) when it cannot be loaded.
std::string nvrtc_version(std::string* why = nullptr);

/// The kernel cache's folder, `<cache>/kernels` (core/cache_directory.h: created 0700, and
/// refused with a warning when another user owns it or others can write to it); empty when
/// the cache is off or refused.
std::string kernel_cache_dir();

}  // namespace lucent::cuda

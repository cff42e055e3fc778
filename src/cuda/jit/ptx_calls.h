// Which functions of a PTX module call each other: the call graph NVRTC left after inlining,
// read from the PTX text. The megakernel compiler asks it one question: does trace_ray
// (src/cuda/device/lucent_gpu/trace.cuh) reach itself, i.e. does a program that a trace
// runs (closest hit, any hit, miss, intersection, a callable) trace again? Where it does
// not, a kernel may inline trace() into its ray-generation program (no recursion to unroll).
#pragma once

#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace lucent::cuda {

/// Each function defined in the PTX (`.func` or `.entry`, with a body) and the defined
/// functions its body names: the targets of its calls. Declarations without a body (a
/// `.func` prototype ending in `;`, `.extern`) are not functions of the module.
using PtxCallGraph = std::map<std::string, std::set<std::string>>;

PtxCallGraph ptx_call_graph(std::string_view ptx);

/// The functions of `graph` that lie on a cycle of calls (call themselves, directly or
/// through others), sorted.
std::vector<std::string> recursive_functions(const PtxCallGraph& graph);

}  // namespace lucent::cuda

#include "cuda/jit/megakernel_compiler.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <set>
#include <thread>

namespace lucent::cuda {

ProgramTable build_program_table(const core::CompiledScene& scene) {
    ProgramTable table;
    for (const core::CompiledEntry& e : scene.entries) {
        table.id(e.ray_generation);
        table.id(e.exception);
    }
    for (const core::CompiledProgram& m : scene.miss) table.id(m);
    for (const core::CompiledInstance& inst : scene.instances) {
        table.id(inst.intersection);
        table.id(inst.attribute);
        for (const core::CompiledMaterial& m : inst.materials)
            for (size_t r = 0; r < m.closest_hit.size(); ++r) {
                table.id(m.closest_hit[r]);
                table.id(m.any_hit[r]);
            }
    }
    for (const core::CompiledNode& n : scene.nodes) table.id(n.visit);
    for (const core::CompiledProgram& c : scene.callables) table.id(c);
    return table;
}

std::string Megakernel::text() const {
    std::string all = source;
    for (const std::string& k : kernels) all += k;
    return all;
}

Megakernel generate_megakernel(const core::CompiledScene& scene, const ProgramTable& table) {
    Megakernel k;
    k.shape = kernel_shape(scene);
    k.modules = bound_module_sources(table, scene.module_sources);
    k.source = generate_megakernel(table, k.shape, k.modules);
    const size_t ray_generations = table.programs(ProgramKind::kRayGeneration).size();
    for (size_t i = 0; i < ray_generations; ++i)
        k.kernels.push_back(ray_generation_kernel_definition(table, int(i)));
    // LUCENT_DUMP_MEGAKERNEL=file: keep the generated source (every kernel) for inspection.
    if (const char* dump = std::getenv("LUCENT_DUMP_MEGAKERNEL")) {
        std::ofstream out(dump);
        out << k.text();
    }
    return k;
}

std::vector<CompileRequest> unit_requests(const Megakernel& k, int sm,
                                          const std::vector<size_t>& kernels,
                                          const std::vector<std::string>& extra_options) {
    std::vector<CompileRequest> requests;
    for (size_t i : kernels) {
        CompileRequest request =
            embedded_request("lucent_megakernel.cu", k.source + k.kernels.at(i),
                             {"--std=c++20", "-default-device", "--use_fast_math"}, sm);
        std::set<std::string> names;  // two modules may include one file
        for (const auto& module : k.modules)
            for (const auto& [name, text] : module->files)
                if (names.insert(name).second) request.headers.emplace_back(name, text);
        // LUCENT_NVRTC_OPTIONS="-DLUCENT_GPU_MIN_BLOCKS=8 ...": tuning experiments.
        add_options_from_env(request, "LUCENT_NVRTC_OPTIONS");
        for (const std::string& o : extra_options) request.options.push_back(o);
        requests.push_back(std::move(request));
    }
    return requests;
}

std::vector<CompileResult> compile_units(const std::vector<CompileRequest>& requests) {
    // The units are independent NVRTC programs: compiled side by side, a scene of several
    // ray-generation programs takes about as long as its largest one on a machine with the
    // cores (ptxas would otherwise compile trace_ray once per kernel, one after another).
    std::vector<CompileResult> binaries(requests.size());
    std::vector<std::exception_ptr> errors(requests.size());
    std::atomic<size_t> next{0};
    const auto work = [&] {
        for (size_t i; (i = next++) < requests.size();) {
            try {
                binaries[i] = compile_cubin(requests[i]);
            } catch (...) {
                errors[i] = std::current_exception();
            }
        }
    };
    // At most 8 at once: each NVRTC program holds a few hundred megabytes while it compiles.
    const size_t threads = std::min<size_t>(
        {requests.size(), std::max(1u, std::thread::hardware_concurrency()), size_t(8)});
    std::vector<std::thread> pool;
    for (size_t t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
    for (const std::exception_ptr& e : errors)
        if (e) std::rethrow_exception(e);
    return binaries;
}

bool can_inline_trace(const CompileResult& binary) {
    if (!binary.call_graph_known) return false;
    // trace_ray's mangled name: lucent::gpu::trace_ray(...), whatever its parameters.
    const auto trace = std::find_if(
        binary.call_graph.begin(), binary.call_graph.end(),
        [](const auto& f) { return f.first.starts_with("_ZN6lucent3gpu9trace_ray"); });
    if (trace == binary.call_graph.end()) return false;
    const std::vector<std::string> recursive = recursive_functions(binary.call_graph);
    return std::find(recursive.begin(), recursive.end(), trace->first) == recursive.end();
}

void compile_megakernel(Megakernel& k, int sm) {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    std::vector<size_t> all(k.kernels.size());
    for (size_t i = 0; i < all.size(); ++i) all[i] = i;
    k.binaries = compile_units(unit_requests(k, sm, all, {}));
    k.from_cache = !k.binaries.empty();
    for (const CompileResult& b : k.binaries) k.from_cache = k.from_cache && b.from_cache;
    k.jit_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

}  // namespace lucent::cuda

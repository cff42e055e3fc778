#include "cuda/jit/megakernel_compiler.h"

#include <cstdlib>
#include <fstream>
#include <set>

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

Megakernel generate_megakernel(const core::CompiledScene& scene, const ProgramTable& table) {
    Megakernel k;
    k.shape = kernel_shape(scene);
    k.modules = bound_module_sources(table, scene.module_sources);
    k.source = generate_megakernel(table, k.shape, k.modules);
    // LUCENT_DUMP_MEGAKERNEL=file: keep the generated source for inspection.
    if (const char* dump = std::getenv("LUCENT_DUMP_MEGAKERNEL")) {
        std::ofstream out(dump);
        out << k.source;
    }
    return k;
}

void compile_megakernel(Megakernel& k, int sm) {
    CompileRequest request =
        embedded_request("lucent_megakernel.cu", k.source,
                         {"--std=c++20", "-default-device", "--use_fast_math"}, sm);
    std::set<std::string> names;  // two modules may include one file
    for (const auto& module : k.modules)
        for (const auto& [name, text] : module->files)
            if (names.insert(name).second) request.headers.emplace_back(name, text);
    // LUCENT_NVRTC_OPTIONS="-DLUCENT_GPU_MIN_BLOCKS=8 ...": tuning experiments.
    add_options_from_env(request, "LUCENT_NVRTC_OPTIONS");
    k.binary = compile_cubin(request);
}

}  // namespace lucent::cuda

#include "cuda/jit/megakernel_generator.h"

#include <algorithm>
#include <set>
#include <string_view>
#include <sstream>

#include "lucent/error.h"

namespace lucent::cuda {

int ProgramTable::id(const core::CompiledProgram& program) {
    if (!program) return -1;
    size_t kind = size_t(program.desc->kind);
    auto [it, inserted] = m_ids[kind].emplace(program.desc, int(m_lists[kind].size()));
    if (inserted) m_lists[kind].push_back(program.desc);
    return it->second;
}

KernelShape kernel_shape(const core::CompiledScene& scene) {
    KernelShape shape;
    for (const core::CompiledNode& n : scene.nodes) {
        shape.groups |= n.kind == NodeKind::kGroup;
        shape.transforms |= n.kind == NodeKind::kTransform;
        shape.selectors |= n.kind == NodeKind::kSelector;
        if (n.kind == NodeKind::kGeometryGroup && n.geometry) {
            shape.generic_geometry |= !n.geometry->triangles_only;
            shape.triangle_groups |= n.geometry->triangles_only;
        }
    }
    size_t attributes = 16;
    for (const core::CompiledInstance& inst : scene.instances) {
        attributes = std::max(attributes, inst.attributes->size);
        shape.spheres |= inst.type == PrimitiveType::kSpheres;
        shape.curves |= inst.type == PrimitiveType::kCurves;
    }
    shape.attribute_bytes = unsigned((attributes + 15) / 16 * 16);
    shape.exceptions = !scene.enabled_exceptions.empty();
    shape.print = scene.print_enabled;
    shape.occlusion = scene.uses_occluded;
    shape.ray_control = scene.needs_ray_control();
    shape.motion = scene.has_motion();
    shape.max_depth = scene.max_depth;
    return shape;
}

namespace {
const char* kind_function(ProgramKind kind) {
    switch (kind) {
        // Ray generation has no switch: a kernel per program (ray_generation_kernel).
        case ProgramKind::kException:
            return "__device__ void dispatch_exception(int id, const void* rec, const "
                   "ExceptionInfo& ex)";
        case ProgramKind::kMiss:
            return "__device__ void dispatch_miss(int id, const void* rec, void* prd)";
        case ProgramKind::kClosestHit:
            return "__device__ void dispatch_closest_hit(int id, const void* rec, void* prd, const "
                   "void* attr)";
        case ProgramKind::kAnyHit:
            return "__device__ void dispatch_any_hit(int id, const void* rec, void* prd, const "
                   "void* attr)";
        case ProgramKind::kIntersection:
            return "__device__ void dispatch_intersection(int id, const void* rec, unsigned prim, "
                   "void* attr)";
        case ProgramKind::kVisit:
            return "__device__ unsigned dispatch_visit(int id, const void* rec)";
        case ProgramKind::kAttribute:
            return "__device__ void dispatch_attribute(int id, const void* rec, unsigned prim, "
                   "float2 bary, void* attr)";
        default:
            return nullptr;
    }
}
const char* kind_call(ProgramKind kind) {
    switch (kind) {
        case ProgramKind::kException:
            return "invoke(&::%s, rec, ex)";
        case ProgramKind::kMiss:
            return "invoke(&::%s, rec, prd)";
        case ProgramKind::kClosestHit:
        case ProgramKind::kAnyHit:
            return "invoke(&::%s, rec, prd, attr)";
        case ProgramKind::kIntersection:
            return "invoke(&::%s, rec, prim, attr)";
        case ProgramKind::kVisit:
            return "return invoke_visit(&::%s, rec)";
        case ProgramKind::kAttribute:
            return "invoke(&::%s, rec, prim, bary, attr)";
        default:
            return nullptr;
    }
}
std::string format_call(const char* pattern, const ProgramDesc& desc) {
    std::string s(pattern);
    s.replace(s.find("%s"), 2, std::string(desc.scope) + std::string(desc.name));
    return s;
}
/// Splits a function type's name, "float3(const float3&, int)", into its result type and
/// parameter types (commas inside <>, () or [] do not split).
bool split_signature(std::string_view sig, std::string& result, std::vector<std::string>& params) {
    size_t open = sig.find('(');
    if (open == std::string_view::npos || sig.empty() || sig.back() != ')') return false;
    result = std::string(sig.substr(0, open));
    while (!result.empty() && result.back() == ' ') result.pop_back();
    std::string_view inside = sig.substr(open + 1, sig.size() - open - 2);
    int depth = 0;
    std::string current;
    for (char c : inside) {
        if (c == '<' || c == '(' || c == '[') ++depth;
        if (c == '>' || c == ')' || c == ']') --depth;
        if (c == ',' && depth == 0) {
            params.push_back(current);
            current.clear();
        } else if (!(current.empty() && c == ' ')) {
            current += c;
        }
    }
    if (!current.empty() && current != "void") params.push_back(current);
    return true;
}

/// One function per callable signature, found by Callable::operator() through ADL on
/// CallableTag<Signature>: a switch over the callables of that signature.
void generate_callables(std::ostringstream& out, const std::vector<const ProgramDesc*>& list) {
    std::map<std::string_view, std::vector<size_t>> by_signature;
    for (size_t i = 0; i < list.size(); ++i) by_signature[list[i]->signature->name].push_back(i);
    out << "namespace lucent::detail {\n";
    for (const auto& [sig, ids] : by_signature) {
        std::string result;
        std::vector<std::string> params;
        if (!split_signature(sig, result, params))
            throw Error("callable program '" + std::string(list[ids[0]]->name) +
                        "' has a signature the CUDA backend cannot spell: " + std::string(sig));
        out << "__device__ " << result << " lucent_gpu_call(CallableTag<" << sig
            << ">, unsigned id, unsigned record";
        std::string args;
        for (size_t a = 0; a < params.size(); ++a) {
            out << ", " << params[a] << " a" << a;
            args += ", a" + std::to_string(a);
        }
        out << ") {\n    const void* rec = ::lucent::gpu::params.records + record;\n"
            << "    switch (id) {\n";
        for (size_t i : ids)
            out << "        case " << i
                << ": return ::lucent::gpu::invoke_callable(&::" << list[i]->scope << list[i]->name
                << ", rec" << args << ");\n";
        out << "        default: break;\n    }\n";
        if (result != "void") out << "    return " << result << "{};\n";
        out << "}\n";
    }
    out << "}  // namespace lucent::detail\n";
}

}  // namespace

ModuleSourceList bound_module_sources(
    const ProgramTable& table,
    const std::map<const ModuleInfo*, std::shared_ptr<const ModuleSource>>& given) {
    ModuleSourceList modules;
    std::set<const ModuleInfo*> seen;
    for (size_t k = 0; k <= size_t(ProgramKind::kCallable); ++k)
        for (const ProgramDesc* desc : table.programs(ProgramKind(k))) {
            if (!seen.insert(desc->module).second) continue;
            if (auto it = given.find(desc->module); it != given.end()) {
                modules.push_back(it->second);
                continue;
            }
            const std::string name = desc->module ? std::string(desc->module->name()) : "";
            if (const ModuleSource* embedded = embedded_module_source(name)) {
                // The embedded texts live as long as the program: a non-owning pointer.
                modules.emplace_back(std::shared_ptr<const ModuleSource>(), embedded);
                continue;
            }
            throw Error(std::string(program_kind_name(desc->kind)) + " program '" +
                        std::string(desc->name) + "' of module '" + name + "' (" + desc->file +
                        ") cannot run on the GPU: the CUDA backend has no text of the module. "
                        "Embed it at build time with lucent_add_programs(<your target> HEADERS " +
                        desc->file + ") in CMake, or give it at run time with "
                        "context.add_module(lucent::ModuleSource::from_file(\"" + desc->file +
                        "\")); or run on the CPU (--backend cpu)");
        }
    return modules;
}

std::string ray_generation_kernel(int id) {
    return "lucent_ray_generation_" + std::to_string(id);
}

std::string ray_generation_kernel_definition(const ProgramTable& table, int id) {
    const ProgramDesc& program = *table.programs(ProgramKind::kRayGeneration).at(size_t(id));
    return "LUCENT_GPU_RAY_GENERATION_KERNEL(" + ray_generation_kernel(id) + ", ::" +
           std::string(program.scope) + std::string(program.name) + ")\n";
}

std::string generate_megakernel(const ProgramTable& table, const KernelShape& shape,
                                const ModuleSourceList& modules) {
    std::ostringstream out;
    out << "// Lucent megakernel: generated for one scene shape; do not edit.\n"
        << "#define LUCENT_GPU_GROUPS " << shape.groups << "\n"
        << "#define LUCENT_GPU_TRANSFORMS " << shape.transforms << "\n"
        << "#define LUCENT_GPU_SELECTORS " << shape.selectors << "\n"
        << "#define LUCENT_GPU_GENERIC_GEOMETRY " << shape.generic_geometry << "\n"
        << "#define LUCENT_GPU_TRIANGLE_GROUPS " << shape.triangle_groups << "\n"
        << "#define LUCENT_GPU_SPHERES " << shape.spheres << "\n"
        << "#define LUCENT_GPU_CURVES " << shape.curves << "\n"
        << "#define LUCENT_GPU_EXCEPTIONS " << shape.exceptions << "\n"
        << "#define LUCENT_GPU_PRINT " << shape.print << "\n"
        << "#define LUCENT_GPU_OCCLUSION " << shape.occlusion << "\n"
        << "#define LUCENT_GPU_RAY_CONTROL " << shape.ray_control << "\n"
        << "#define LUCENT_GPU_MOTION " << shape.motion << "\n"
        << "#define LUCENT_GPU_MAX_DEPTH " << shape.max_depth << "\n"
        << "#define LUCENT_GPU_ATTRIBUTE_BYTES " << shape.attribute_bytes << "\n"
        << "#include \"lucent_gpu/runtime.cuh\"\n"
        << "#include \"lucent_gpu/invoke.cuh\"\n";
    for (const auto& m : modules) out << "#include \"" << m->main << "\"\n";

    out << "\nnamespace lucent::gpu {\n";
    for (size_t k = 0; k < size_t(ProgramKind::kCallable); ++k) {
        ProgramKind kind = ProgramKind(k);
        const char* fn = kind_function(kind);
        if (!fn) continue;
        out << fn << " {\n    switch (id) {\n";
        const auto& list = table.programs(kind);
        for (size_t i = 0; i < list.size(); ++i)
            out << "        case " << i << ": " << format_call(kind_call(kind), *list[i])
                << "; break;\n";
        out << "        default: break;\n    }\n";
        if (kind == ProgramKind::kVisit) out << "    return ~0u;\n";
        out << "}\n";
    }
    out << "}  // namespace lucent::gpu\n\n";
    generate_callables(out, table.programs(ProgramKind::kCallable));
    out << "\n#include \"lucent_gpu/trace.cuh\"\n\n";
    return out.str();
}

}  // namespace lucent::cuda

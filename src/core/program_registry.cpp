// Name → ProgramDesc registry filled by the program macros at static-initialisation time.
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "lucent/error.h"
#include "lucent/program.h"

namespace lucent {
namespace {
struct Registry {
    std::mutex mutex;
    std::multimap<std::string, const ProgramDesc*, std::less<>> by_name;
};
Registry& registry() {
    static Registry r;  // function-local: safe during static initialisation
    return r;
}
}  // namespace

namespace detail {
bool register_program(const ProgramDesc& desc) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    r.by_name.emplace(std::string(desc.name), &desc);
    return true;
}
}  // namespace detail

const ProgramDesc& find_program(std::string_view name) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    auto [first, last] = r.by_name.equal_range(name);
    if (first == last) {
        std::string known;
        for (auto& [n, d] : r.by_name) known += (known.empty() ? "" : ", ") + n;
        throw Error("no program named '" + std::string(name) +
                    "' is registered; define it with a LUCENT_* program macro in a module "
                    "that this binary includes (known programs: " +
                    (known.empty() ? "none" : known) + ")");
    }
    if (std::next(first) != last)
        throw Error("program name '" + std::string(name) + "' is defined in " +
                    first->second->file + " and " + std::next(first)->second->file +
                    "; rename one, or pass the program with LUCENT_PROGRAM(name)");
    return *first->second;
}

const char* program_kind_name(ProgramKind kind) {
    switch (kind) {
        case ProgramKind::kRayGeneration:
            return "ray generation";
        case ProgramKind::kException:
            return "exception";
        case ProgramKind::kMiss:
            return "miss";
        case ProgramKind::kIntersection:
            return "intersection";
        case ProgramKind::kBoundingBox:
            return "bounding box";
        case ProgramKind::kClosestHit:
            return "closest hit";
        case ProgramKind::kAnyHit:
            return "any hit";
        case ProgramKind::kVisit:
            return "selector visit";
        case ProgramKind::kAttribute:
            return "attribute";
        case ProgramKind::kCallable:
            return "callable";
    }
    return "?";
}

const char* field_kind_name(FieldKind kind) {
    switch (kind) {
        case FieldKind::kFloat:
            return "float";
        case FieldKind::kFloat2:
            return "float2";
        case FieldKind::kFloat3:
            return "float3";
        case FieldKind::kFloat4:
            return "float4";
        case FieldKind::kInt:
            return "int";
        case FieldKind::kInt2:
            return "int2";
        case FieldKind::kInt3:
            return "int3";
        case FieldKind::kInt4:
            return "int4";
        case FieldKind::kUint:
            return "unsigned";
        case FieldKind::kUint2:
            return "uint2";
        case FieldKind::kUint3:
            return "uint3";
        case FieldKind::kUint4:
            return "uint4";
        case FieldKind::kMatrix4x3:
            return "Matrix4x3";
        case FieldKind::kBuffer:
            return "BufferView";
        case FieldKind::kTexture:
            return "TextureView";
        case FieldKind::kHandle:
            return "Handle (a node)";
        case FieldKind::kCallable:
            return "Callable";
        case FieldKind::kUserData:
            return "user data";
    }
    return "?";
}

Program::Program(detail::OwnerRef owner, const ProgramDesc& desc)
    : ContextObject(std::move(owner), std::string(desc.name)), m_desc(&desc) {}

std::string Program::describe() const {
    return std::string(program_kind_name(m_desc->kind)) + " program '" + name() + "'";
}

}  // namespace lucent

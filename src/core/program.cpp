// Names of program and field kinds, and the host handle of a program.
#include "lucent/error.h"
#include "lucent/program.h"

namespace lucent {

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

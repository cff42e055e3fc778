// Variable values and scopes.
#include "lucent/variables.h"

#include "lucent/buffer.h"
#include "lucent/nodes.h"
#include "lucent/program.h"

namespace lucent {

std::string VariableValue::describe() const {
    switch (kind) {
        case FieldKind::kBuffer:
            return buffer ? buffer->describe() : "a null buffer";
        case FieldKind::kTexture:
            return texture ? texture->describe() : "a null texture";
        case FieldKind::kHandle:
            return node ? node->describe() : "a null node";
        case FieldKind::kCallable:
            return program ? program->describe() : "a null program";
        case FieldKind::kUserData:
            return "user data " + std::string(user_type ? user_type->name : "?");
        default:
            return field_kind_name(kind);
    }
}

VariableRef& VariableRef::set(VariableValue value) {
    m_scope.m_variables[m_name] = std::move(value);
    m_scope.variables_changed();
    return *this;
}

VariableRef& VariableRef::operator=(std::shared_ptr<Buffer> buffer) {
    VariableValue v;
    v.kind = FieldKind::kBuffer;
    v.buffer = std::move(buffer);
    return set(std::move(v));
}

VariableRef& VariableRef::operator=(std::shared_ptr<TextureSampler> texture) {
    VariableValue v;
    v.kind = FieldKind::kTexture;
    v.texture = std::move(texture);
    return set(std::move(v));
}

VariableRef& VariableRef::operator=(std::shared_ptr<Program> callable) {
    VariableValue v;
    v.kind = FieldKind::kCallable;
    v.program = std::move(callable);
    return set(std::move(v));
}

VariableRef& VariableRef::set_node(std::shared_ptr<Node> node) {
    VariableValue v;
    v.kind = FieldKind::kHandle;
    v.node = std::move(node);
    return set(std::move(v));
}

const VariableValue* VariableScope::find_variable(const std::string& name) const {
    auto it = m_variables.find(name);
    return it == m_variables.end() ? nullptr : &it->second;
}

void VariableScope::remove_variable(const std::string& name) {
    if (m_variables.erase(name)) variables_changed();
}

}  // namespace lucent

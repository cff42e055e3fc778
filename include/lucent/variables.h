// Variables: values set by name on a scope (Context, Program, GeometryInstance, Material,
// Geometry), resolved into each program's record when the scene is compiled, in the
// OptiX scope order (OptiX paper §3.2).
#pragma once

#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "lucent/device/reflect.h"
#include "lucent/error.h"
#include "lucent/object.h"

namespace lucent {

class Buffer;
class TextureSampler;
class Node;
class Program;

/// One variable's value: a typed scalar/vector/matrix/user struct, or an object reference.
struct VariableValue {
    FieldKind kind = FieldKind::kFloat;
    const TypeInfo* user_type = nullptr;  // kUserData: the struct type
    std::vector<unsigned char> bytes;     // value bytes for plain kinds and user data
    std::shared_ptr<Buffer> buffer;
    std::shared_ptr<TextureSampler> texture;
    std::shared_ptr<Node> node;
    std::shared_ptr<Program> program;

    /// What the value holds, for messages: "float3", "Buffer 'lights'", "user data Light".
    std::string describe() const;
};

template <class T>
VariableValue make_plain_value(const T& value) {
    VariableValue v;
    v.kind = FieldKindOf<T>::value;
    if (v.kind == FieldKind::kUserData) v.user_type = &type_info_of<T>();
    v.bytes.resize(sizeof(T));
    std::memcpy(v.bytes.data(), &value, sizeof(T));
    return v;
}

class VariableScope;

/// `scope["name"] = value;` — assigns a variable by name.
class VariableRef {
  public:
    VariableRef(VariableScope& scope, std::string name) : m_scope(scope), m_name(std::move(name)) {}
    VariableRef& operator=(float v) { return set(make_plain_value(v)); }
    VariableRef& operator=(float2 v) { return set(make_plain_value(v)); }
    VariableRef& operator=(float3 v) { return set(make_plain_value(v)); }
    VariableRef& operator=(float4 v) { return set(make_plain_value(v)); }
    VariableRef& operator=(int v) { return set(make_plain_value(v)); }
    VariableRef& operator=(int2 v) { return set(make_plain_value(v)); }
    VariableRef& operator=(int3 v) { return set(make_plain_value(v)); }
    VariableRef& operator=(int4 v) { return set(make_plain_value(v)); }
    VariableRef& operator=(unsigned v) { return set(make_plain_value(v)); }
    VariableRef& operator=(uint2 v) { return set(make_plain_value(v)); }
    VariableRef& operator=(uint3 v) { return set(make_plain_value(v)); }
    VariableRef& operator=(uint4 v) { return set(make_plain_value(v)); }
    VariableRef& operator=(const Matrix4x3& v) { return set(make_plain_value(v)); }
    VariableRef& operator=(std::shared_ptr<Buffer> buffer);
    VariableRef& operator=(std::shared_ptr<TextureSampler> texture);
    VariableRef& operator=(std::shared_ptr<Program> callable);
    template <class N, class = std::enable_if_t<std::is_base_of_v<Node, N>>>
    VariableRef& operator=(std::shared_ptr<N> node) {
        return set_node(std::static_pointer_cast<Node>(std::move(node)));
    }
    /// A plain struct value (a record field of that struct type).
    template <class T>
    VariableRef& set_user(const T& value) {
        static_assert(std::is_trivially_copyable_v<T>, "user data must be trivially copyable");
        return set(make_plain_value(value));
    }
    VariableRef& set(VariableValue value);

  private:
    VariableRef& set_node(std::shared_ptr<Node> node);
    VariableScope& m_scope;
    std::string m_name;
};

/// Something that holds variables by name.
class VariableScope {
  public:
    virtual ~VariableScope() = default;
    VariableRef operator[](std::string name) { return VariableRef(*this, std::move(name)); }
    /// The value set here, or null.
    const VariableValue* find_variable(const std::string& name) const;
    void remove_variable(const std::string& name);
    const std::map<std::string, VariableValue>& variables() const { return m_variables; }
    /// How the scope names itself in messages ("Material 'glass'", "Context").
    virtual std::string scope_name() const = 0;

  protected:
    virtual void variables_changed() {}

  private:
    friend class VariableRef;
    std::map<std::string, VariableValue> m_variables;
};

}  // namespace lucent

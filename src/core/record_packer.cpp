// Variable resolution and record packing (docs/architecture.md, "Scene compile"): each field of a program's
// record is looked up by name through its scope chain at compile time and written into
// the record, so programs never look a variable up at run time.
#include <cstring>

#include "core/scene_compiler.h"

namespace lucent::core {

namespace {
std::string chain_names(const ScopeChain& chain) {
    std::string s;
    for (int i = 0; i < chain.count; ++i)
        s += (i == 0 ? "" : i + 1 == chain.count ? " or " : ", ") + chain.scopes[i]->scope_name();
    return s;
}

bool is_integer_kind(FieldKind k, int& lanes, bool& is_signed) {
    switch (k) {
        case FieldKind::kInt:
            lanes = 1;
            is_signed = true;
            return true;
        case FieldKind::kInt2:
            lanes = 2;
            is_signed = true;
            return true;
        case FieldKind::kInt3:
            lanes = 3;
            is_signed = true;
            return true;
        case FieldKind::kInt4:
            lanes = 4;
            is_signed = true;
            return true;
        case FieldKind::kUint:
            lanes = 1;
            is_signed = false;
            return true;
        case FieldKind::kUint2:
            lanes = 2;
            is_signed = false;
            return true;
        case FieldKind::kUint3:
            lanes = 3;
            is_signed = false;
            return true;
        case FieldKind::kUint4:
            lanes = 4;
            is_signed = false;
            return true;
        default:
            return false;
    }
}

/// int ↔ unsigned of the same width converts when the value fits, so `rec.count` may be
/// unsigned while the host writes `mat["count"] = 3`.
bool convert_integers(const FieldInfo& field, const VariableValue& value, unsigned char* dst) {
    int field_lanes, value_lanes;
    bool field_signed, value_signed;
    if (!is_integer_kind(field.kind, field_lanes, field_signed) ||
        !is_integer_kind(value.kind, value_lanes, value_signed) || field_lanes != value_lanes)
        return false;
    for (int i = 0; i < field_lanes; ++i) {
        int32_t v;
        std::memcpy(&v, value.bytes.data() + 4 * i, 4);
        if (field_signed != value_signed && v < 0) return false;
    }
    std::memcpy(dst, value.bytes.data(), 4 * size_t(field_lanes));
    return true;
}
}  // namespace

CompiledProgram SceneCompiler::pack(const std::shared_ptr<Program>& program,
                                    const ScopeChain& scopes, const std::string& owner,
                                    std::vector<const Buffer*>* output_buffers) {
    CompiledProgram out;
    if (!program) return out;
    ScopeChain chain;
    chain.then(program.get());
    for (int i = 0; i < scopes.count; ++i) chain.then(scopes.scopes[i]);

    const RecordInfo& info = *program->desc().record;
    out.desc = &program->desc();
    // occluded() is there only when a module declares it: the same rule on both backends.
    const ModuleInfo* module = out.desc->module;
    m_scene->uses_occluded = m_scene->uses_occluded || (module && module->uses(kUsesOccluded));
    m_scene->uses_ray_flags = m_scene->uses_ray_flags || (module && module->uses(kUsesRayFlags));
    out.label = program->describe() + (owner.empty() ? "" : " of " + owner);
    out.record = std::make_shared<PackedRecord>();
    out.record->resize(info.size);
    for (const FieldInfo& field : info.fields) {
        const VariableValue* value = nullptr;
        for (int i = 0; i < chain.count && !value; ++i)
            value = chain.scopes[i]->find_variable(std::string(field.name));
        if (!value)
            throw Error(out.label + ": variable '" + std::string(field.name) + "' (" +
                        field_kind_name(field.kind) + ") is not set on " + chain_names(chain) +
                        "; set it on one of them, e.g. context[\"" + std::string(field.name) +
                        "\"] = ...");
        pack_field(field, *value, out.record->data() + field.offset, out.label, output_buffers);
        if (value->kind == FieldKind::kBuffer) {
            out.buffers.push_back(value->buffer);
            if (!field.read_only) out.writable_buffers.push_back(value->buffer);
        }
        if (value->kind == FieldKind::kTexture) {
            out.buffers.push_back(value->texture->buffer());
            m_rebuild_inputs.push_back(value->texture->buffer().get());  // GPU texture objects
        }
    }
    return out;
}

void SceneCompiler::pack_field(const FieldInfo& field, const VariableValue& value,
                               unsigned char* dst, const std::string& label,
                               std::vector<const Buffer*>* output_buffers) {
    // Where the field is, for messages: built only for one, not for every field packed.
    const auto where = [&] { return label + ", variable '" + std::string(field.name) + "'"; };
    auto mismatch = [&](const std::string& expected) {
        return Error(where() + ": the record field is " + expected + " but the variable holds " +
                     value.describe() + "; set it to a " + expected);
    };
    const bool checked = m_scene->exception_enabled(kExceptionBufferIndexOutOfBounds);
    switch (field.kind) {
        case FieldKind::kBuffer: {
            if (value.kind != FieldKind::kBuffer || !value.buffer)
                throw mismatch("buffer of " + std::string(field.element->name));
            const Buffer& b = *value.buffer;
            if (!same_type(b.element(), *field.element))
                throw Error(where() + ": the program reads BufferView<" +
                            std::string(field.element->name) + "> but " + b.describe() + " holds " +
                            std::string(b.element().name) +
                            "; bind a buffer created with that element type");
            BufferView<unsigned char> view{
                const_cast<unsigned char*>(static_cast<const unsigned char*>(b.raw())), b.size(),
                checked ? unsigned(kViewBoundsChecked) : 0u};
            std::memcpy(dst, &view, sizeof view);
            // Only pure output buffers must match the launch: input-output ones are often
            // images of another size that the program reads (IGI's G-buffer, accumulators).
            if (output_buffers && b.type() == BufferType::kOutput) output_buffers->push_back(&b);
            return;
        }
        case FieldKind::kTexture: {
            if (value.kind != FieldKind::kTexture || !value.texture)
                throw mismatch("texture sampler");
            const TextureSampler& t = *value.texture;
            if (!t.buffer())
                throw Error(where() + ": " + t.describe() +
                            " has no texels; give it a 2D float4 buffer with set_buffer");
            TextureView view{t.buffer()->data<float4>(),
                             t.buffer()->size().x,
                             t.buffer()->size().y,
                             t.wrap_u(),
                             t.wrap_v(),
                             t.filter()};
            std::memcpy(dst, &view, sizeof view);
            return;
        }
        case FieldKind::kHandle: {
            if (value.kind != FieldKind::kHandle || !value.node)
                throw mismatch("node (Group, GeometryGroup, Transform or Selector)");
            Handle h{node_index(value.node)};
            std::memcpy(dst, &h, sizeof h);
            return;
        }
        case FieldKind::kCallable: {
            if (value.kind != FieldKind::kCallable || !value.program)
                throw mismatch("callable program of signature " + std::string(field.element->name));
            const Program& p = *value.program;
            if (p.kind() != ProgramKind::kCallable)
                throw Error(where() + ": " + p.describe() +
                            " is not a callable program; define it with LUCENT_CALLABLE");
            if (!same_type(*p.desc().signature, *field.element))
                throw Error(where() + ": the field wants a callable of signature " +
                            std::string(field.element->name) + " but " + p.describe() + " is " +
                            std::string(p.desc().signature->name));
            auto record = pack_callable(value.program, where());
            // Callable<Sig> is {fn, record}; the fn pointer type is erased here.
            struct ErasedCallable {
                void (*fn)();
                const void* record;
            } c{p.desc().entry, record->data()};
            std::memcpy(dst, &c, sizeof c);
            return;
        }
        case FieldKind::kUserData: {
            if (value.kind != FieldKind::kUserData || !value.user_type ||
                !same_type(*value.user_type, *field.element))
                throw mismatch(std::string(field.element->name) + " (set it with set_user)");
            std::memcpy(dst, value.bytes.data(), field.size);
            return;
        }
        default:
            if (value.kind == field.kind && value.bytes.size() == field.size) {
                std::memcpy(dst, value.bytes.data(), field.size);
                return;
            }
            if (convert_integers(field, value, dst)) return;
            throw mismatch(field_kind_name(field.kind));
    }
}

std::shared_ptr<PackedRecord> SceneCompiler::pack_callable(const std::shared_ptr<Program>& program,
                                                           const std::string& where) {
    auto it = m_callables.find(program.get());
    if (it != m_callables.end()) return it->second;
    // Register before packing so a callable that refers to itself resolves to this record.
    auto record = std::make_shared<PackedRecord>();
    record->resize(program->desc().record->size);  // its address is final from here on
    m_callables[program.get()] = record;
    const size_t index = m_scene->callables.size();
    m_scene->callables.emplace_back();  // the scene keeps the record alive
    ScopeChain chain;
    chain.then(m_state.context);
    CompiledProgram packed = pack(program, chain, "a variable (" + where + ")");
    std::memcpy(record->data(), packed.record->data(), record->size());
    packed.record = record;
    m_scene->callables[index] = std::move(packed);
    return record;
}

}  // namespace lucent::core

// The launch digest (core/launch_digest.h). What is hashed is what every rank must agree on
// and nothing that may differ between correct ranks: host addresses in records (buffer
// views, callables) and the contents of buffers launches write are left out; a buffer is
// named by its name, type and size instead. Input buffers' contents are hashed once per
// version (a scene's vertices: a few milliseconds per new version).
#include "core/launch_digest.h"

#include <cstring>
#include <string_view>

#include "core/launch_buffers.h"

namespace lucent::core {

namespace {

/// 64-bit mixing of 8-byte words (the finaliser of MurmurHash3 over a running state).
struct Hasher {
    uint64_t state = 0x9e3779b97f4a7c15ull;
    void word(uint64_t w) {
        state ^= w + 0x9e3779b97f4a7c15ull + (state << 6) + (state >> 2);
        state ^= state >> 33;
        state *= 0xff51afd7ed558ccdull;
        state ^= state >> 33;
    }
    void bytes(const void* data, size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        size_t i = 0;
        for (; i + 8 <= n; i += 8) {
            uint64_t w;
            std::memcpy(&w, p + i, 8);
            word(w);
        }
        uint64_t tail = 0;
        if (i < n) std::memcpy(&tail, p + i, n - i);
        word(tail ^ (uint64_t(n) << 56));
    }
    void text(std::string_view s) { bytes(s.data(), s.size()); }
};

void hash_buffer_shape(Hasher& h, const Buffer& b) {
    h.text(b.name());
    h.word(uint64_t(b.type()));
    h.word(b.element().size);
    h.word(b.dimensionality());
    h.word((uint64_t(b.size().x) << 32) ^ b.size().y);
    h.word(b.size().z);
}

}  // namespace

uint64_t LaunchDigest::contents(const Buffer& buffer) {
    const size_t bytes = buffer.count() * buffer.element().size;
    const auto key = std::make_tuple(&buffer, buffer.version(), bytes);
    auto found = m_contents.find(key);
    if (found != m_contents.end()) return found->second;
    if (m_contents.size() > 4096) m_contents.clear();
    Hasher h;
    if (bytes) h.bytes(buffer.raw(), bytes);
    return m_contents[key] = h.state;
}

uint64_t LaunchDigest::of(const CompiledScene& scene, const LaunchSpec& spec) {
    Hasher h;
    h.word(spec.entry);
    h.word((uint64_t(spec.size.x) << 32) ^ spec.size.y);
    h.word(spec.size.z);
    // The first device slot's key: the seed's (every rank's slot 0 has the same one).
    if (!spec.device_keys.empty()) h.bytes(&spec.device_keys[0], sizeof(uint4));
    h.word(scene.nodes.size());
    h.word(scene.instances.size());
    for (const CompiledNode& n : scene.nodes) {
        h.word(uint64_t(n.kind));
        h.word(n.children.size());
        for (unsigned c : n.children) h.word(c);
        for (unsigned i : n.instances) h.word(i);
        h.bytes(&n.to_world, sizeof n.to_world);
        h.word(n.visibility_mask);
    }
    for (const CompiledInstance& inst : scene.instances) {
        h.word(uint64_t(inst.type));
        h.word(inst.primitive_count);
        h.word(inst.materials.size());
    }
    for (const auto& [buffer, version] : scene.rebuild_inputs) {
        hash_buffer_shape(h, *buffer);
        h.word(contents(*buffer));
    }
    h.bytes(scene.motion.data(), scene.motion.size() * sizeof(float));
    for_each_program(scene, spec.entry, [&](const CompiledProgram& p) {
        if (!p) {
            h.word(0);
            return;
        }
        h.text(p.label);
        const unsigned char* record = static_cast<const unsigned char*>(p.rec());
        size_t buffer_field = 0;
        for (const FieldInfo& field : p.desc->record->fields) {
            h.text(field.name);
            switch (field.kind) {
                case FieldKind::kBuffer: {
                    // p.buffers holds the record's buffers and textures' texels in field order.
                    const Buffer& b = *p.buffers[buffer_field++];
                    hash_buffer_shape(h, b);
                    if (b.type() == BufferType::kInput) h.word(contents(b));
                    break;
                }
                case FieldKind::kTexture: {
                    const Buffer& b = *p.buffers[buffer_field++];
                    hash_buffer_shape(h, b);
                    h.word(contents(b));
                    break;
                }
                case FieldKind::kCallable:  // a host address; the program's label is in the
                                            // callables
                    break;
                default:  // values, node handles (indices), user structs
                    h.bytes(record + field.offset, field.size);
            }
        }
    });
    return h.state;
}

}  // namespace lucent::core

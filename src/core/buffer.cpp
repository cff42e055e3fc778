// Buffer and TextureSampler host objects.
#include "lucent/buffer.h"

namespace lucent {

const char* buffer_type_name(BufferType type) {
    switch (type) {
        case BufferType::kInput:
            return "input";
        case BufferType::kOutput:
            return "output";
        case BufferType::kInputOutput:
            return "input-output";
    }
    return "?";
}

std::string ContextObject::describe() const {
    return "object '" + m_name + "'";
}

Buffer::Buffer(detail::OwnerRef owner, std::string name, BufferType type, const TypeInfo& element,
               unsigned dimensionality, uint3 size)
    : ContextObject(std::move(owner), std::move(name)),
      m_type(type),
      m_element(&element),
      m_dimensionality(dimensionality),
      m_size{1, 1, 1} {
    if (element.align > 16)
        throw Error(describe() + ": element type " + std::string(element.name) +
                    " needs alignment " + std::to_string(element.align) +
                    "; buffers support at most 16");
    resize(size.x, size.y, size.z);
}

std::string Buffer::describe() const {
    return "Buffer '" + name() + "' (" + buffer_type_name(m_type) + ", " +
           std::string(m_element->name) + ", " + std::to_string(m_size.x) +
           (m_dimensionality > 1 ? "x" + std::to_string(m_size.y) : "") +
           (m_dimensionality > 2 ? "x" + std::to_string(m_size.z) : "") + ")";
}

void Buffer::resize(unsigned width, unsigned height, unsigned depth) {
    if ((m_dimensionality < 2 && height != 1) || (m_dimensionality < 3 && depth != 1))
        throw Error(describe() + ": resize to " + std::to_string(width) + "x" +
                    std::to_string(height) + "x" + std::to_string(depth) + " does not fit a " +
                    std::to_string(m_dimensionality) +
                    "D buffer; leave the unused dimensions at 1");
    m_size = uint3{width, height, depth};
    m_device_newer = false;
    m_zeroed = true;
    size_t bytes = count() * m_element->size;
    m_blocks.assign((bytes + sizeof(Block) - 1) / sizeof(Block), Block{});
    ++m_version;
    changed();
}

void Buffer::check_element(const TypeInfo& requested) const {
    if (!same_type(requested, *m_element))
        throw Error(describe() + ": accessed as " + std::string(requested.name) +
                    " but its elements are " + std::string(m_element->name) + "; map it with map<" +
                    std::string(m_element->name) + ">()");
}

void Buffer::sync_from_device() const {
    if (!m_device_newer) return;
    m_device_newer = false;
    if (m_owner->fetch_from_device) m_owner->fetch_from_device(*this);
}

void Buffer::unmap() {
    m_mapped = false;
    ++m_version;
    ++m_owner->data_generation;  // new contents: uploaded at the next launch, not recompiled
}

std::string TextureSampler::describe() const {
    return "TextureSampler '" + name() + "'";
}

void TextureSampler::set_buffer(std::shared_ptr<Buffer> texels) {
    if (texels &&
        (texels->dimensionality() != 2 || !same_type(texels->element(), type_info_of<float4>())))
        throw Error(describe() + ": texels must be a 2D buffer of float4, got " +
                    texels->describe());
    m_buffer = std::move(texels);
    changed();
}

void TextureSampler::set_wrap_mode(WrapMode u, WrapMode v) {
    m_wrap_u = u;
    m_wrap_v = v;
    changed();
}

void TextureSampler::set_filter(FilterMode filter) {
    m_filter = filter;
    changed();
}

}  // namespace lucent

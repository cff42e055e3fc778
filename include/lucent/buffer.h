// Buffers (typed 1D/2D/3D arrays shared by host and programs) and texture samplers.
#pragma once

#include <cstring>
#include <memory>
#include <vector>

#include "lucent/device/reflect.h"
#include "lucent/error.h"
#include "lucent/object.h"

namespace lucent {

enum class BufferType { kInput, kOutput, kInputOutput };
const char* buffer_type_name(BufferType type);

/// A typed array. Element type is fixed at creation; map<T>() checks it.
class Buffer : public ContextObject {
  public:
    Buffer(detail::OwnerRef owner, std::string name, BufferType type, const TypeInfo& element,
           unsigned dimensionality, uint3 size);

    BufferType type() const { return m_type; }
    const TypeInfo& element() const { return *m_element; }
    unsigned dimensionality() const { return m_dimensionality; }
    uint3 size() const { return m_size; }
    size_t count() const { return size_t(m_size.x) * m_size.y * m_size.z; }
    std::string describe() const override;

    /// Resize, keeping the dimensionality (unused dimensions must be 1). Contents are zeroed.
    void resize(unsigned width, unsigned height = 1, unsigned depth = 1);

    /// Host access to the elements; T must be the element type the buffer was created with.
    template <class T>
    T* map() {
        check_element(type_info_of<T>());
        sync_from_device();
        m_mapped = true;
        m_zeroed = false;
        return reinterpret_cast<T*>(bytes());
    }
    template <class T>
    const T* data() const {
        check_element(type_info_of<T>());
        sync_from_device();
        return reinterpret_cast<const T*>(bytes());
    }
    /// Ends host access: programs see the new contents at the next launch.
    void unmap();
    /// Copy `values` in (sizes must match) — map, copy, unmap in one call.
    template <class T>
    void upload(const std::vector<T>& values) {
        if (values.size() != count())
            throw Error(describe() + ": upload of " + std::to_string(values.size()) +
                        " elements into a buffer of " + std::to_string(count()) +
                        "; resize the buffer first");
        T* mapped = map<T>();
        // memcpy's pointers must be valid even for no bytes; an empty vector's data() may
        // be null (UBSan: "null pointer passed as argument 2").
        if (!values.empty()) std::memcpy(mapped, values.data(), values.size() * sizeof(T));
        unmap();
    }

    /// Declares that launches read and write element i of this launch-shaped buffer only
    /// at launch index i (an accumulation buffer; OptiX's RT_BUFFER_GPU_LOCAL serves the
    /// same purpose across GPUs). A Context spanning ranks then keeps each rank's elements
    /// where they were computed, launch after launch of one entry point and size, and
    /// gathers them only when something else reads the buffer: another launch, or a host
    /// read, which is then collective (every rank must make it; docs/distributed.md,
    /// "Index-local buffers"). No effect in one process.
    void set_launch_index_local(bool local) { m_launch_index_local = local; }
    bool launch_index_local() const { return m_launch_index_local; }

    /// The host copy, as it is (backends use these; applications use map/data).
    void* raw() {
        m_zeroed = false;
        return bytes();
    }
    const void* raw() const { return bytes(); }
    uint64_t version() const { return m_version; }
    /// Nothing has written the contents since the last resize, so they are all zeros: a
    /// backend may clear its device copy instead of copying the host's bytes (a launch's
    /// output images are often hundreds of MB).
    bool zeroed() const { return m_zeroed; }
    /// Something other than map() or upload() may have written the host copy: a launch that
    /// views the buffer writably, or a device copy fetched into it.
    void mark_written() const { m_zeroed = false; }
    /// A GPU launch wrote the buffer: the host copy is refreshed on the next map or data.
    void mark_device_newer() const {
        m_device_newer = true;
        m_zeroed = false;
    }
    /// Brings the host copy up to date now if a launch wrote the buffer on a device.
    void sync_from_device() const;

  private:
    void check_element(const TypeInfo& requested) const;
    /// The host copy starts on a cache line. The CPU backend's workers write neighbouring
    /// pieces of a launch's output (64 launch indices each in 1D); starting mid-line, each
    /// piece shared its first and last lines with the pieces beside it, often another
    /// worker's, and every such write moved the line between cores: `bench rays --programs`
    /// shadow rays (one byte each) ran up to 12 % slower on two threads (docs/performance.md).
    struct alignas(64) Block {
        unsigned char bytes[64];
    };
    unsigned char* bytes() { return m_blocks.empty() ? nullptr : m_blocks[0].bytes; }
    const unsigned char* bytes() const { return m_blocks.empty() ? nullptr : m_blocks[0].bytes; }
    BufferType m_type;
    const TypeInfo* m_element;
    unsigned m_dimensionality;
    uint3 m_size;
    std::vector<Block> m_blocks;  // cache-line aligned backing store
    bool m_mapped = false;
    mutable bool m_device_newer = false;
    mutable bool m_zeroed = true;  // see zeroed()
    bool m_launch_index_local = false;
    uint64_t m_version = 1;
};

/// A 2D float4 texture with filtering and wrap modes, read by programs via TextureView.
class TextureSampler : public ContextObject {
  public:
    using ContextObject::ContextObject;
    std::string describe() const override;

    /// The texels: a 2D Buffer of float4.
    void set_buffer(std::shared_ptr<Buffer> texels);
    void set_wrap_mode(WrapMode u, WrapMode v);
    void set_filter(FilterMode filter);

    const std::shared_ptr<Buffer>& buffer() const { return m_buffer; }
    WrapMode wrap_u() const { return m_wrap_u; }
    WrapMode wrap_v() const { return m_wrap_v; }
    FilterMode filter() const { return m_filter; }

  private:
    std::shared_ptr<Buffer> m_buffer;
    WrapMode m_wrap_u = WrapMode::kRepeat, m_wrap_v = WrapMode::kRepeat;
    FilterMode m_filter = FilterMode::kLinear;
};

}  // namespace lucent

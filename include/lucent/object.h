// Base of every object a Context creates: a readable name for messages, and the link
// back to the context so any change marks the compiled scene stale.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace lucent {

class Buffer;

namespace detail {
/// State every object of one context shares: a generation bumped on every change of the
/// scene's shape, a data generation bumped when a buffer's contents change, and the
/// backend's hook that copies a buffer the GPU wrote back to the host when it is read.
/// Objects hold it by shared_ptr, so they may outlive their Context safely.
struct ContextShared {
    uint64_t generation = 1;
    /// New buffer contents need no recompile, only an upload; unless an acceleration
    /// structure or a texture is built from that buffer (CompiledScene::rebuild_inputs).
    uint64_t data_generation = 1;
    std::function<void(const Buffer&)> fetch_from_device;
};
using OwnerRef = std::shared_ptr<ContextShared>;
}  // namespace detail

class ContextObject {
  public:
    ContextObject(detail::OwnerRef owner, std::string name)
        : m_owner(std::move(owner)), m_name(std::move(name)) {}
    virtual ~ContextObject() = default;
    ContextObject(const ContextObject&) = delete;
    ContextObject& operator=(const ContextObject&) = delete;

    /// Name used in error messages, e.g. "Material 'glass'".
    const std::string& name() const { return m_name; }
    void set_name(std::string name) { m_name = std::move(name); }
    /// Type name plus name, for messages: "Material 'glass'".
    virtual std::string describe() const;
    const detail::OwnerRef owner() const { return m_owner; }

  protected:
    void changed() { ++m_owner->generation; }
    detail::OwnerRef m_owner;

  private:
    std::string m_name;
};

}  // namespace lucent

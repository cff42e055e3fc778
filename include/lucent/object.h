// Base of every object a Context creates: a readable name for messages, and the link
// back to the context so any change marks the compiled scene stale.
#pragma once

#include <cstdint>
#include <string>

namespace lucent {

namespace detail {
/// State every object of one context shares: bumped on every change.
struct ContextShared {
    uint64_t generation = 1;
};
}  // namespace detail

class ContextObject {
public:
    ContextObject(detail::ContextShared* owner, std::string name)
        : m_owner(owner), m_name(std::move(name)) {}
    virtual ~ContextObject() = default;
    ContextObject(const ContextObject&) = delete;
    ContextObject& operator=(const ContextObject&) = delete;

    /// Name used in error messages, e.g. "Material 'glass'".
    const std::string& name() const { return m_name; }
    void set_name(std::string name) { m_name = std::move(name); }
    /// Type name plus name, for messages: "Material 'glass'".
    virtual std::string describe() const;
    const detail::ContextShared* owner() const { return m_owner; }

protected:
    void changed() { ++m_owner->generation; }
    detail::ContextShared* m_owner;

private:
    std::string m_name;
};

}  // namespace lucent

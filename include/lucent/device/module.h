// A program module: one header of programs (and the headers it includes) that declares
// itself with LUCENT_MODULE(name, uses...) in the namespace of its programs. The program
// macros of lucent/device/program.h register each program with the module whose
// declaration their namespace sees, so two modules may both define `closest_hit` (each in
// its own namespace), and what the GPU's code generator needs to know of a module (its
// programs, whether it asks occluded()) comes from these declarations, not from its text.
//
//   namespace my_renderer {
//   LUCENT_MODULE(my_renderer, lucent::kUsesOccluded)
//   LUCENT_CLOSEST_HIT(closest_hit, Record, Payload, Attributes) { ... }
//   }
//
// The module's text reaches the GPU backend either at build time (lucent_add_programs in
// CMake embeds it into your target) or at run time (Context::add_module with a
// ModuleSource); lucent/module.h has the host side.
#pragma once

#include "lucent/device/platform.h"

namespace lucent {

/// Device-API features a module declares it uses (LUCENT_MODULE's optional arguments).
enum ModuleUses : unsigned {
    kUsesNothing = 0,
    /// A program calls occluded(): the GPU traversal keeps its any-hit early exit. A module
    /// that calls occluded() without declaring it does not compile for the GPU.
    kUsesOccluded = 1u << 0,
    /// A program passes ray flags or a visibility mask to trace() or occluded() (their
    /// fourth and fifth arguments): the GPU megakernel keeps the per-ray control code, which
    /// it otherwise compiles out unless the scene has masks, ids or opaque geometry (OptiX
    /// paper §4.3). A module that passes them without declaring it does not compile for the
    /// GPU, and the CPU refuses the launch.
    kUsesRayFlags = 1u << 1,
};

namespace detail {
/// False, but only once T is known: a static_assert that fires when a template is used.
template <class T>
constexpr bool dependent_false = false;

/// The flags LUCENT_MODULE's optional arguments name, or'ed together (none: 0).
template <class... Flags>
constexpr unsigned module_uses(Flags... flags) {
    return (0u | ... | unsigned(flags));
}
}  // namespace detail

}  // namespace lucent

#if !LUCENT_GPU_CODE
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

namespace lucent {

struct ProgramDesc;

/// What the host knows of a module compiled into this binary: its name, the file that
/// declares it, its declared features and its programs (filled as the program macros'
/// registrations run at static initialisation).
class ModuleInfo {
  public:
    ModuleInfo(const char* name, const char* file, unsigned uses)
        : m_name(name), m_file(file), m_uses(uses) {}
    ModuleInfo(const ModuleInfo&) = delete;
    ModuleInfo& operator=(const ModuleInfo&) = delete;

    std::string_view name() const { return m_name; }
    /// The header with the LUCENT_MODULE declaration, as the compiler named it.
    const char* file() const { return m_file; }
    unsigned uses() const { return m_uses; }
    bool uses(ModuleUses feature) const { return (m_uses & feature) != 0; }

    /// The module's programs, in registration order.
    std::vector<const ProgramDesc*> programs() const;
    /// The program named `name` (unqualified, as its macro spells it), or null.
    const ProgramDesc* find(std::string_view name) const;

    /// Called by the program macros; returns true so it can initialise a variable.
    bool add(const ProgramDesc& desc);

  private:
    const char* m_name;
    const char* m_file;
    unsigned m_uses;
    mutable std::mutex m_mutex;
    std::vector<const ProgramDesc*> m_programs;
};

namespace detail {
/// Adds `module` to this binary's list of modules (find_module, program_desc_of).
bool register_module(ModuleInfo& module);
}  // namespace detail
}  // namespace lucent

/// Program macros used outside any LUCENT_MODULE find this instead of a module, and stop
/// the build with the fix.
template <class NoModuleDeclared = void>
::lucent::ModuleInfo& lucent_this_module() {
    static_assert(::lucent::detail::dependent_false<NoModuleDeclared>,
                  "Lucent: a program macro is used outside a module; declare "
                  "LUCENT_MODULE(name) in the namespace of your programs "
                  "(see docs/programming-model.md, 'Program modules')");
    return *static_cast<::lucent::ModuleInfo*>(nullptr);
}

/// Declares the module of the programs in this namespace (and the namespaces inside it).
/// Its name is the module's identity in this binary and in the GPU's JIT; the optional
/// arguments are ModuleUses flags.
#define LUCENT_MODULE(name, ...)                                                         \
    inline ::lucent::ModuleInfo& lucent_this_module() {                                  \
        static ::lucent::ModuleInfo info(#name, __FILE__,                                \
                                         ::lucent::detail::module_uses(__VA_ARGS__));    \
        return info;                                                                     \
    }                                                                                    \
    inline const bool lucent_module_registered_##name =                                  \
        ::lucent::detail::register_module(lucent_this_module());

#else  // GPU code: the module is already part of the megakernel; its facts are on the host.
#define LUCENT_MODULE(name, ...)
#endif

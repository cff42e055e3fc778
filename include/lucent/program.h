// Host handle of a program: its description (kind, types, entry) and its own variables.
#pragma once

#include <memory>
#include <string_view>

#include "lucent/device/program.h"
#include "lucent/object.h"
#include "lucent/variables.h"

/// The ProgramDesc of a program defined with a LUCENT_* macro, by its C++ name.
#define LUCENT_PROGRAM(name) lucent_program_desc_##name()

namespace lucent {

class Program : public ContextObject, public VariableScope {
  public:
    Program(detail::OwnerRef owner, const ProgramDesc& desc);
    const ProgramDesc& desc() const { return *m_desc; }
    ProgramKind kind() const { return m_desc->kind; }
    std::string describe() const override;
    std::string scope_name() const override { return describe(); }

  protected:
    void variables_changed() override { changed(); }

  private:
    const ProgramDesc* m_desc;
};

/// The registered program with this name (defined by a LUCENT_* macro in any linked
/// module), or an Error listing the names that exist.
const ProgramDesc& find_program(std::string_view name);

}  // namespace lucent

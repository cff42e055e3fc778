// Host handle of a program: its description (kind, types, entry) and its own variables.
#pragma once

#include <memory>
#include <string_view>

#include "lucent/device/program.h"
#include "lucent/module.h"
#include "lucent/object.h"
#include "lucent/variables.h"

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

}  // namespace lucent

// Program modules compiled at run time for the host: Context::add_module(ModuleSource) of a
// module that is not compiled into the program. Its text is compiled with the system's C++
// compiler into a shared library, which is loaded into the process; its programs register
// themselves as a compiled-in module's do (LUCENT_MODULE, at the library's static
// initialisation). The CPU backend runs them from there, and every backend takes their
// records, payloads and attributes from their registration.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "lucent/module.h"

namespace lucent::core {

/// The module `source` declares, compiled and loaded (or loaded from the cache, or found
/// already loaded with the same text). Throws Error when no compiler is found, when the
/// compiler rejects the text (its messages name the module's files and lines), when this
/// process loaded a different text under the same module name, or when the program cannot
/// lend its symbols to the library (an executable built without ENABLE_EXPORTS).
const ModuleInfo& load_runtime_module(const ModuleSource& source);

/// Whether module `name` was compiled at run time by this process (load_runtime_module).
bool is_runtime_module(std::string_view name);

/// The command that compiles modules: $LUCENT_CXX, else $CXX, else the first of c++, g++,
/// clang++ on PATH (split into words); empty when none is found.
std::vector<std::string> module_compiler_command();

}  // namespace lucent::core

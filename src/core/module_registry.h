// What the module registry (module_registry.cpp) offers the core beyond lucent/module.h.
#pragma once

#include <string>

namespace lucent::detail {
/// The names of the modules this binary contains, for messages: "a, b, c" or "none".
std::string known_module_names();
}  // namespace lucent::detail

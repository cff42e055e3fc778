#include "lucent/version.h"

namespace lucent {
const char* version() {
    return LUCENT_VERSION;  // the project's version, from CMake
}
}  // namespace lucent

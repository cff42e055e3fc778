// The library's version, as the package was built ("0.1"; find_package(Lucent 0.1)).
#pragma once

namespace lucent {
const char* version();
}

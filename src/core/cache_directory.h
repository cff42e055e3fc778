// Where Lucent keeps what it compiles at run time (GPU kernels, CPU program modules).
#pragma once

#include <string>

namespace lucent::core {

/// $LUCENT_CACHE_DIR, else $XDG_CACHE_HOME/lucent, else ~/.cache/lucent; empty when
/// LUCENT_CACHE_DIR=off or no home is known (nothing is cached then).
std::string cache_directory();

/// `cache_directory()/sub`, created with mode 0700 (only its owner can plant files in it)
/// if it is missing; empty when caching is off or the folder cannot be made or is not
/// owned by this user (a cache only costs speed when it is absent).
std::string private_cache_subdirectory(const std::string& sub);

}  // namespace lucent::core

// A loader's progress through a large file, for a caller that shows it (the CLI draws a bar
// on a terminal); the loaders in scene/ print nothing themselves.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace lucent::scene {

/// Called as a file is read: `stage` says what is being done ("checking big.obj"), `done`
/// of `total` bytes. A new stage starts again from 0. May be empty.
using LoadProgress =
    std::function<void(const std::string& stage, uint64_t done, uint64_t total)>;

}  // namespace lucent::scene

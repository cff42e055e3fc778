// A 64-bit digest of what a launch computes from: its entry point, size and random seed,
// every program's variables, the scene graph's shape and the contents of its input
// buffers. Ranks compare digests before each launch (docs/distributed.md, "Divergence and
// faults"), so a rank whose host code diverged is an error, not a wrong image.
#pragma once

#include <cstdint>
#include <map>
#include <tuple>

#include "core/backend.h"

namespace lucent::core {

class LaunchDigest {
  public:
    uint64_t of(const CompiledScene& scene, const LaunchSpec& spec);

  private:
    /// The contents' hash of an input buffer, computed once per version.
    uint64_t contents(const Buffer& buffer);
    std::map<std::tuple<const Buffer*, uint64_t, size_t>, uint64_t> m_contents;
};

}  // namespace lucent::core

// The interface every backend implements: run one launch of a compiled scene.
#pragma once

#include <memory>
#include <string>

#include "core/compiled_scene.h"

namespace lucent::core {

class Backend {
  public:
    virtual ~Backend() = default;
    /// "cpu (2 threads)", for the user.
    virtual std::string name() const = 0;
    /// Runs entry point `entry` over the grid `size`; fills the exception part of `report`.
    virtual void launch(const CompiledScene& scene, unsigned entry, uint3 size,
                        LaunchReport& report) = 0;
    /// Brings the host copy of a buffer that the last launch wrote on a device up to date.
    virtual void fetch(const Buffer& /*buffer*/) {}
};

/// The CPU backend: a worker per core (or `threads`), tiles of the launch grid.
std::unique_ptr<Backend> make_cpu_backend(unsigned threads);

}  // namespace lucent::core

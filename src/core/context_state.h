// What a Context holds, as the scene compiler and backends read it.
#pragma once

#include <memory>
#include <unordered_map>
#include <vector>

#include "core/compiled_scene.h"
#include "lucent/context.h"
#include "lucent/module.h"

namespace lucent::core {

struct EntryPoint {
    std::shared_ptr<Program> ray_generation;
    std::shared_ptr<Program> exception;
};

/// A module a context knows, with the text it was given at run time (else null: the GPU
/// backend takes the text lucent_add_programs embedded).
struct ContextModule {
    const ModuleInfo* info = nullptr;
    std::shared_ptr<const ModuleSource> source;
};

struct ContextState {
    const Context* context = nullptr;  // the Context's own variable scope
    std::vector<ContextModule> modules;
    std::vector<EntryPoint> entries{1};
    std::vector<RayTypeDesc> ray_types;          // a gap has payload == nullptr
    std::vector<std::shared_ptr<Program>> miss;  // per ray type
    unsigned max_depth = 8;
    std::vector<int> enabled_exceptions;  // codes, or kAllExceptions
    bool print_enabled = false;
    int3 print_index{-1, -1, -1};
};

/// Acceleration data kept across compiles, per GeometryGroup.
using AccelCache = std::unordered_map<const GeometryGroup*, std::shared_ptr<GeometryAccel>>;

}  // namespace lucent::core

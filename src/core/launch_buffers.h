// What a launch may read and write, read from its programs' records: shared by the
// multi-device backend and the distributed one (docs/multi-device.md, "What a program may
// write").
#pragma once

#include <memory>
#include <set>
#include <vector>

#include "core/compiled_scene.h"

namespace lucent::core {

/// Calls add(program) for every program a launch of `entry` can run: its ray-generation
/// and exception programs, and every program a trace can reach.
template <class Fn>
void for_each_program(const CompiledScene& scene, unsigned entry, const Fn& add) {
    add(scene.entries[entry].ray_generation);
    add(scene.entries[entry].exception);
    for (const CompiledProgram& p : scene.miss) add(p);
    for (const CompiledProgram& p : scene.callables) add(p);
    for (const CompiledNode& n : scene.nodes) add(n.visit);
    for (const CompiledInstance& inst : scene.instances) {
        add(inst.intersection);
        add(inst.attribute);
        for (const CompiledMaterial& m : inst.materials) {
            for (const CompiledProgram& p : m.closest_hit) add(p);
            for (const CompiledProgram& p : m.any_hit) add(p);
        }
    }
}

using BufferList = std::vector<std::shared_ptr<const Buffer>> CompiledProgram::*;

/// The buffers not of type input that a launch of `entry` views through `list`:
/// CompiledProgram::writable_buffers (those it may write: BufferView<T>, not
/// BufferView<const T>) or CompiledProgram::buffers (those it may read or write).
inline std::vector<std::shared_ptr<const Buffer>> launch_buffers(const CompiledScene& scene,
                                                                 unsigned entry, BufferList list) {
    std::set<const Buffer*> seen;
    std::vector<std::shared_ptr<const Buffer>> out;
    for_each_program(scene, entry, [&](const CompiledProgram& p) {
        for (const auto& b : p.*list)
            if (b && b->type() != BufferType::kInput && seen.insert(b.get()).second)
                out.push_back(b);
    });
    return out;
}

/// A buffer the size and shape of the launch grid: launch index i owns element i, so a
/// piece's part of it is one byte range.
inline bool launch_shaped(const Buffer& b, uint3 size) {
    const unsigned dims = size.z > 1 ? 3 : size.y > 1 ? 2 : 1;
    const uint3 s = b.size();
    return b.dimensionality() == dims && s.x == size.x && s.y == size.y && s.z == size.z;
}

}  // namespace lucent::core

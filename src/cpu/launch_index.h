// What the CPU backend does around each launch index's programs, whether they run in the
// launch loop (the ray-generation program) or later, when the rays the index deferred are
// traced (deferred_rays.h): the thread state set for the index, and an exception raised
// below it counted and handed to the entry point's exception program.
#pragma once

#include <cstdint>
#include <map>

#include "cpu/cpu_state.h"

namespace lucent::cpu {

/// The exceptions one worker saw in a launch: per code, how many and the first launch
/// index (in linear order) that raised it.
struct WorkerExceptions {
    struct Entry {
        uint64_t count = 0;
        uint64_t first_linear = ~0ull;
        uint3 first_index{0, 0, 0};
    };
    std::map<int, Entry> by_code;
    void add(int code, uint3 index, uint64_t linear) {
        Entry& e = by_code[code];
        ++e.count;
        if (linear < e.first_linear) {
            e.first_linear = linear;
            e.first_index = index;
        }
    }
};

/// The thread state of a launch index about to run a program outside any trace: its
/// index, no trace open, and whether print() shows its output.
inline void enter_index(ThreadState& ts, uint3 index) {
    const core::CompiledScene& scene = *ts.scene;
    set_launch_index(ts, index);
    ts.depth = 0;
    ts.frame = nullptr;
    ts.context = ProgramContext::kRayGeneration;
    ts.print_here = scene.print_enabled &&
                    (scene.print_index.x < 0 || unsigned(scene.print_index.x) == index.x) &&
                    (scene.print_index.y < 0 || unsigned(scene.print_index.y) == index.y) &&
                    (scene.print_index.z < 0 || unsigned(scene.print_index.z) == index.z);
}

/// After a program of launch index `index` raised `ex` (its traces unwound): counts it and
/// runs the entry point's exception program, when one is bound and the code enabled.
inline void handle_program_exception(ThreadState& ts, const core::CompiledEntry& e, uint3 index,
                                     const ProgramException& ex, WorkerExceptions& out) {
    const core::CompiledScene& scene = *ts.scene;
    const uint64_t linear =
        (uint64_t(index.z) * ts.launch_size.y + index.y) * ts.launch_size.x + index.x;
    out.add(ex.code, index, linear);
    ts.depth = 0;
    ts.frame = nullptr;  // the unwound traces' frames are gone
    if (!e.exception || !scene.exception_enabled(ex.code)) return;
    ts.context = ProgramContext::kException;
    try {
        e.exception.entry<ExceptionFn>()(e.exception.rec(),
                                         ExceptionInfo{ex.code, index, ex.detail});
    } catch (const ProgramException& nested) {
        // An exception program that raises is counted, not re-run.
        out.add(nested.code, index, linear);
    }
}

}  // namespace lucent::cpu

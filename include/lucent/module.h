// Program modules on the host: the modules compiled into this binary, their programs, and
// their source text for the GPU's run-time compiler.
//
// A module (lucent/device/module.h) is compiled by your C++ compiler for the CPU backend
// like any header. The CUDA backend compiles it again, with NVRTC, into the megakernel of
// each scene that binds its programs (OptiX paper §4), and for that it needs the module's
// text. Two ways to give it:
//   - build time: `lucent_add_programs(my_target HEADERS my_programs.h)` in CMake embeds
//     the header, and the headers it includes, into your target;
//   - run time: `context.add_module(lucent::ModuleSource::from_file("my_programs.h"))`.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "lucent/device/module.h"
#include "lucent/device/program.h"

namespace lucent {

/// The text of a module for run-time compilation: its header and every header it includes
/// by a quoted path that is not one of Lucent's own (`lucent/...`). Each file is named by
/// its absolute path, and its quoted includes are rewritten to those names, so NVRTC finds
/// them and its messages name your file and line.
struct ModuleSource {
    std::string module;  // the name its LUCENT_MODULE declares
    std::string main;    // the name of the module's header (files[0].first)
    std::vector<std::pair<std::string, std::string>> files;  // name → text, main first

    /// Reads a module's header and the headers it includes: quoted includes are looked up
    /// beside the including file, then in `include_dirs`. Throws Error naming the file
    /// (and line) that cannot be read, or an include that is not found.
    static ModuleSource from_file(const std::string& path,
                                  const std::vector<std::string>& include_dirs = {});
    /// A module given as text; `name` names it in messages (a path: its quoted includes
    /// are looked up beside it, then in `include_dirs`).
    static ModuleSource from_text(const std::string& name, const std::string& text,
                                  const std::vector<std::string>& include_dirs = {});

    /// The paths of every file read (for build systems' dependency lists).
    std::vector<std::string> paths() const;
    bool same_text(const ModuleSource& other) const { return files == other.files; }
};

/// The module named `name` that this binary contains (its header is included by some file
/// linked in), or null.
const ModuleInfo* find_module(std::string_view name);
/// Every module this binary contains, by name.
std::vector<const ModuleInfo*> modules();

/// The description of the program whose function is `function` (LUCENT_PROGRAM).
const ProgramDesc& program_desc_of(void (*function)(), const char* spelled);
template <class F>
const ProgramDesc& program_desc_of(F* function, const char* spelled) {
    return program_desc_of(reinterpret_cast<void (*)()>(function), spelled);
}

/// The source that `lucent_add_programs` embedded in this binary for module `name`, or
/// null. Throws Error when two different texts were embedded under that name.
const ModuleSource* embedded_module_source(std::string_view name);

namespace detail {
/// Called at static initialisation by the file lucent_add_programs generates.
bool embed_module_source(ModuleSource source);
}  // namespace detail

}  // namespace lucent

/// The ProgramDesc of a program defined with a LUCENT_* macro: LUCENT_PROGRAM(my_ns::shade).
#define LUCENT_PROGRAM(name) ::lucent::program_desc_of(&name, #name)

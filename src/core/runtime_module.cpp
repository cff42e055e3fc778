// Modules compiled at run time for the host (runtime_module.h).
//
// The library a module is compiled into has no copy of the engine: it calls the device API
// and registers its programs through the program that loads it, whose symbols it is linked
// against. Where that program is a shared object (the Python extension, a plugin) the
// library is linked against its path; where it is an executable, the executable must
// export its symbols (CMake's ENABLE_EXPORTS, -rdynamic). Types are compared across the two
// by name, size and alignment (same_type in lucent/device/reflect.h), as each has its own
// TypeInfo objects. A loaded library is never unloaded: the registry holds its programs.
#include "core/runtime_module.h"

#include <dlfcn.h>
#include <link.h>
#include <stdlib.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <regex>
#include <sstream>

#include "core/cache_directory.h"
#include "core/cache_key.h"
#include "core/child_process.h"
#include "core/device_headers.h"
#include "lucent/error.h"

namespace lucent::core {
namespace fs = std::filesystem;

namespace {

/// The flags every module is compiled with; $LUCENT_CXXFLAGS adds to them (include folders
/// of third-party headers a module includes with <...>, -march=native).
std::vector<std::string> compile_flags() {
    std::vector<std::string> flags{"-std=c++20", "-O3", "-DNDEBUG", "-fPIC", "-shared",
                                   "-fvisibility=hidden", "-fvisibility-inlines-hidden"};
    if (const char* extra = std::getenv("LUCENT_CXXFLAGS")) {
        std::istringstream words(extra);
        for (std::string w; words >> w;) flags.push_back(w);
    }
    return flags;
}

/// The object file (executable or shared library) that holds this engine, as the dynamic
/// linker names it: "" for the executable. `exported`: whether its symbols are visible to
/// libraries it loads (dladdr only sees exported symbols).
struct HostObject {
    std::string path;
    bool exported = false;
};
HostObject host_object() {
    HostObject host;
    void* anchor = reinterpret_cast<void*>(&detail::register_module);
    Dl_info info{};
    link_map* map = nullptr;
    if (dladdr1(anchor, &info, reinterpret_cast<void**>(&map), RTLD_DL_LINKMAP) && map)
        host.path = map->l_name ? map->l_name : "";
    host.exported = info.dli_saddr == anchor;
    return host;
}

std::string compiler_identity(const std::vector<std::string>& compiler, const fs::path& scratch) {
    std::vector<std::string> argv = compiler;
    argv.push_back("--version");
    ChildResult r = run_child_process(argv, (scratch / "version.log").string());
    if (!r.started || r.exit_code != 0)
        throw Error("cannot run the C++ compiler '" + compiler.front() +
                    "' that compiles program modules for the CPU backend (" + r.output +
                    "); install one (apt install g++) or name it in LUCENT_CXX");
    return compiler.front() + "\n" + r.output;
}

/// Copies of the module's files for the compiler: each starts with a #line naming the
/// original, so the compiler's messages name the user's file and line, and its quoted
/// includes of the module's other files name their copies.
void stage_module(const ModuleSource& source, const fs::path& dir) {
    std::map<std::string, std::string> staged_name;
    for (size_t i = 0; i < source.files.size(); ++i)
        staged_name[source.files[i].first] = "module_file_" + std::to_string(i) + ".h";
    static const std::regex include_line(R"(^(\s*#\s*include\s*")([^"]+)(".*)$)");
    for (auto& [name, text] : source.files) {
        std::ostringstream out;
        out << "#pragma once\n#line 1 \"" << std::regex_replace(name, std::regex(R"(["\\])"), "\\$&")
            << "\"\n";
        std::istringstream lines(text);
        for (std::string line; std::getline(lines, line);) {
            std::smatch m;
            if (std::regex_match(line, m, include_line) && staged_name.count(m[2].str()))
                line = m[1].str() + staged_name[m[2].str()] + m[3].str();
            out << line << '\n';
        }
        std::ofstream(dir / staged_name[name], std::ios::binary) << out.str();
    }
    std::ofstream(dir / "module.cpp") << "#include \"" << staged_name[source.main] << "\"\n";
    for (const EmbeddedSource& h : device_headers()) {
        fs::path file = dir / "include" / std::string(h.name);
        fs::create_directories(file.parent_path());
        std::ofstream(file, std::ios::binary) << h.text;
    }
}

/// A scratch folder (removed when this goes out of scope).
struct ScratchDirectory {
    fs::path path;
    explicit ScratchDirectory(const std::string& parent) {
        std::string base = parent.empty() ? fs::temp_directory_path().string() : parent;
        std::string pattern = base + "/lucent-module-XXXXXX";
        if (!::mkdtemp(pattern.data()))
            throw Error("cannot make a folder in " + base + " to compile a program module in (" +
                        std::strerror(errno) + "); set TMPDIR or LUCENT_CACHE_DIR to a "
                        "writable folder");
        path = pattern;
    }
    ~ScratchDirectory() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

void* open_library(const fs::path& file, const HostObject& host, const std::string& module,
                   const std::string& compiler, bool throw_on_failure) {
    void* handle = ::dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle || !throw_on_failure) return handle;
    std::string why = ::dlerror();
    // An engine symbol it cannot find: the executable does not export them. Anything else
    // (a C library newer than the one loaded, a damaged file) is about the library itself.
    std::string fix = host.path.empty() && why.find("undefined symbol") != std::string::npos
                          ? "; the program that loads it must export its symbols: "
                            "set_target_properties(<your target> PROPERTIES ENABLE_EXPORTS ON) "
                            "in CMake (the -rdynamic link flag)"
                          : "; the compiler (" + compiler +
                                ") must build for the C and C++ libraries this program runs "
                                "with: name the right one in LUCENT_CXX";
    throw Error("cannot load program module '" + module + "' compiled at run time: " + why + fix);
}

struct LoadedModules {
    std::mutex mutex;
    std::map<std::string, ModuleSource, std::less<>> source_by_module;  // by module name
};
LoadedModules& loaded_modules() {
    static LoadedModules loaded;
    return loaded;
}

}  // namespace

std::vector<std::string> module_compiler_command() {
    std::vector<std::string> words;
    for (const char* variable : {"LUCENT_CXX", "CXX"}) {
        const char* value = std::getenv(variable);
        if (!value || !*value) continue;
        std::istringstream in(value);
        for (std::string w; in >> w;) words.push_back(w);
        if (!words.empty()) return words;
    }
    std::string found = find_executable({"c++", "g++", "clang++"});
    if (!found.empty()) words.push_back(found);
    return words;
}

bool is_runtime_module(std::string_view name) {
    LoadedModules& loaded = loaded_modules();
    std::lock_guard lock(loaded.mutex);
    return loaded.source_by_module.count(name) != 0;
}

const ModuleInfo& load_runtime_module(const ModuleSource& source) {
    LoadedModules& loaded = loaded_modules();
    std::lock_guard lock(loaded.mutex);
    if (auto it = loaded.source_by_module.find(source.module);
        it != loaded.source_by_module.end()) {
        if (!it->second.same_text(source))
            throw Error("Context::add_module: module '" + source.module + "' (" + source.main +
                        ") was compiled at run time in this process from a different text (" +
                        it->second.main + "); a loaded module cannot be replaced: give the new "
                        "text another LUCENT_MODULE name");
        if (const ModuleInfo* info = find_module(source.module)) return *info;
    }

    const HostObject host = host_object();
    if (host.path.empty() && !host.exported)
        throw Error("Context::add_module: module '" + source.module + "' (" + source.main +
                    ") is not compiled into this program, and it cannot be compiled at run "
                    "time because the program does not export its symbols to the library it "
                    "would be compiled into: set_target_properties(<your target> PROPERTIES "
                    "ENABLE_EXPORTS ON) in CMake (-rdynamic), or compile the module in "
                    "(include its header in one of the program's files)");
    const std::vector<std::string> compiler = module_compiler_command();
    if (compiler.empty())
        throw Error("Context::add_module: module '" + source.module + "' (" + source.main +
                    ") is compiled at run time for the host, and no C++ compiler was found "
                    "(LUCENT_CXX, CXX, or c++, g++, clang++ on PATH); install one "
                    "(apt install g++) or name it in LUCENT_CXX");

    const std::string cache = private_cache_subdirectory("cpu-modules");
    ScratchDirectory scratch(cache);
    const std::vector<std::string> flags = compile_flags();
    CacheKey key;
    key.add(compiler_identity(compiler, scratch.path));
    for (const std::string& f : flags) key.add(f);
    key.add(host.path);
    for (const EmbeddedSource& h : device_headers()) {
        key.add(h.name);
        key.add(h.text);
    }
    for (auto& [name, text] : source.files) {
        key.add(name);
        key.add(text);
    }
    const std::string hex = key.hex();

    const fs::path cached = cache.empty() ? fs::path() : fs::path(cache) / (hex + ".so");
    void* handle = nullptr;
    std::error_code ec;
    if (!cached.empty() && fs::is_regular_file(fs::symlink_status(cached, ec))) {
        handle = open_library(cached, host, source.module, compiler.front(), false);
        if (!handle) fs::remove(cached, ec);  // damaged: compile it again
    }
    if (!handle) {
        stage_module(source, scratch.path);
        const fs::path library = scratch.path / "module.so";
        std::vector<std::string> argv = compiler;
        argv.insert(argv.end(), flags.begin(), flags.end());
        argv.insert(argv.end(), {"-I", (scratch.path / "include").string(), "-o",
                                 library.string(), (scratch.path / "module.cpp").string()});
        if (!host.path.empty()) argv.push_back(host.path);
        ChildResult r = run_child_process(argv, (scratch.path / "compile.log").string());
        if (!r.started || r.exit_code != 0)
            throw Error("Context::add_module: " + compiler.front() + " could not compile module '" +
                        source.module + "' (" + source.main + ") for the CPU backend:\n" +
                        r.output);
        fs::path file = library;
        if (!cached.empty()) {
            fs::rename(library, cached, ec);  // atomic: another process sees all or nothing
            if (!ec) file = cached;
        }
        handle = open_library(file, host, source.module, compiler.front(), true);
    }
    const ModuleInfo* info = find_module(source.module);
    if (!info)
        throw Error("Context::add_module: the library compiled from " + source.main +
                    " registered no module named '" + source.module + "'");
    loaded.source_by_module.emplace(source.module, source);
    return *info;
}

}  // namespace lucent::core

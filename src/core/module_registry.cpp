// The modules compiled into this binary (registered by LUCENT_MODULE at static
// initialisation), their programs, and the module texts lucent_add_programs embedded.
#include <algorithm>
#include <map>
#include <memory>
#include <mutex>

#include "core/module_registry.h"
#include "lucent/error.h"
#include "lucent/module.h"

namespace lucent {
namespace {

struct Registry {
    std::mutex mutex;
    std::multimap<std::string, const ModuleInfo*, std::less<>> modules;
    // Embedded texts by module name; a second, different text is kept to report both.
    std::map<std::string, std::vector<std::unique_ptr<ModuleSource>>, std::less<>> sources;
};
Registry& registry() {
    static Registry r;  // function-local: safe during static initialisation
    return r;
}

}  // namespace

std::vector<const ProgramDesc*> ModuleInfo::programs() const {
    std::lock_guard lock(m_mutex);
    return m_programs;
}

const ProgramDesc* ModuleInfo::find(std::string_view name) const {
    std::lock_guard lock(m_mutex);
    for (const ProgramDesc* p : m_programs)
        if (p->name == name) return p;
    return nullptr;
}

bool ModuleInfo::add(const ProgramDesc& desc) {
    std::lock_guard lock(m_mutex);
    if (std::find(m_programs.begin(), m_programs.end(), &desc) == m_programs.end())
        m_programs.push_back(&desc);
    return true;
}

namespace detail {
bool register_module(ModuleInfo& module) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    r.modules.emplace(std::string(module.name()), &module);
    return true;
}

bool embed_module_source(ModuleSource source) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    auto& list = r.sources[source.module];
    for (const auto& existing : list)
        if (existing->same_text(source)) return true;  // the same text embedded twice
    list.push_back(std::make_unique<ModuleSource>(std::move(source)));
    return true;
}
}  // namespace detail

const ModuleInfo* find_module(std::string_view name) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    auto [first, last] = r.modules.equal_range(name);
    if (first == last) return nullptr;
    if (std::next(first) != last)
        throw Error("two modules are named '" + std::string(name) + "': one declared in " +
                    first->second->file() + ", one in " + std::next(first)->second->file() +
                    "; module names identify modules in a program, rename one "
                    "LUCENT_MODULE");
    return first->second;
}

std::vector<const ModuleInfo*> modules() {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    std::vector<const ModuleInfo*> all;
    for (auto& [name, info] : r.modules) all.push_back(info);
    return all;
}

const ProgramDesc& program_desc_of(void (*function)(), const char* spelled) {
    for (const ModuleInfo* module : modules())
        for (const ProgramDesc* desc : module->programs())
            if (desc->function == function) return *desc;
    throw Error(std::string("LUCENT_PROGRAM(") + spelled +
                "): this function is not a program of any module; define it with a LUCENT_* "
                "program macro inside a LUCENT_MODULE");
}

const ModuleSource* embedded_module_source(std::string_view name) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    auto it = r.sources.find(name);
    if (it == r.sources.end() || it->second.empty()) return nullptr;
    if (it->second.size() > 1)
        throw Error("module '" + std::string(name) + "' is embedded twice with different text: " +
                    it->second[0]->main + " and " + it->second[1]->main +
                    "; give each module its own LUCENT_MODULE name, or embed one of them");
    return it->second.front().get();
}

namespace detail {
std::string known_module_names() {
    std::string names;
    for (const ModuleInfo* module : modules())
        names += (names.empty() ? "" : ", ") + std::string(module->name());
    return names.empty() ? "none" : names;
}
}  // namespace detail

}  // namespace lucent

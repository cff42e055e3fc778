// ModuleSource: a module's header and the headers it includes, read and made self-contained
// for NVRTC (which resolves an #include only against the header names it is given).
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "lucent/error.h"
#include "lucent/module.h"

namespace lucent {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& path, const std::string& wanted_by) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw Error("cannot read the module file " + path.string() +
                    (wanted_by.empty() ? "" : " (included by " + wanted_by + ")") +
                    "; check the path");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

/// Lucent's own device headers are part of every megakernel already; they are never
/// resolved or embedded again (two copies under two names would define everything twice).
bool is_lucent_header(const std::string& include) {
    return include.rfind("lucent/", 0) == 0;
}

class Collector {
  public:
    Collector(ModuleSource& out, const std::vector<std::string>& include_dirs)
        : m_out(out), m_include_dirs(include_dirs) {}

    /// Adds `path` (absolute, normal) with `text`: its quoted includes are resolved,
    /// rewritten to their absolute names and collected in turn.
    void add(const fs::path& path, const std::string& text) {
        m_seen.insert(path.string());  // the main file; an included one is marked when found
        size_t slot = m_out.files.size();
        m_out.files.emplace_back(path.string(), std::string());
        static const std::regex include_line(R"(^(\s*#\s*include\s*")([^"]+)(".*)$)");
        std::istringstream lines(text);
        std::string line, rewritten;
        std::vector<std::pair<fs::path, std::string>> pending;  // (file, included from)
        for (unsigned number = 1; std::getline(lines, line); ++number) {
            std::smatch m;
            if (std::regex_match(line, m, include_line) && !is_lucent_header(m[2].str())) {
                fs::path found = resolve(path, m[2].str(), number);
                line = m[1].str() + found.string() + m[3].str();
                if (m_seen.insert(found.string()).second)
                    pending.emplace_back(found, path.string() + ":" + std::to_string(number));
            }
            rewritten += line;
            rewritten += '\n';
        }
        m_out.files[slot].second = std::move(rewritten);
        for (auto& [file, from] : pending) add(file, read_text(file, from));
    }

  private:
    fs::path resolve(const fs::path& from, const std::string& include, unsigned line) const {
        std::vector<fs::path> candidates{from.parent_path() / include};
        for (const std::string& dir : m_include_dirs) candidates.push_back(fs::path(dir) / include);
        for (const fs::path& c : candidates) {
            std::error_code ec;
            if (fs::is_regular_file(c, ec)) return fs::absolute(c).lexically_normal();
        }
        std::string searched = from.parent_path().string();
        for (const std::string& dir : m_include_dirs) searched += ", " + dir;
        throw Error(from.string() + ":" + std::to_string(line) + ": #include \"" + include +
                    "\" is not found beside the file or in the include directories (" +
                    searched + "); a module includes Lucent's headers as \"lucent/...\" and "
                    "its own by paths relative to itself or to an include directory");
    }

    ModuleSource& m_out;
    const std::vector<std::string>& m_include_dirs;
    std::set<std::string> m_seen;
};

/// The name in the module's one LUCENT_MODULE(name, ...) declaration.
std::string declared_module(const std::string& file, const std::string& text) {
    static const std::regex declaration(R"(^\s*LUCENT_MODULE\(\s*([A-Za-z_][A-Za-z0-9_]*))");
    std::istringstream lines(text);
    std::string line, name;
    unsigned first_line = 0;
    for (unsigned number = 1; std::getline(lines, line); ++number) {
        std::smatch m;
        if (!std::regex_search(line, m, declaration)) continue;
        if (!name.empty())
            throw Error(file + ":" + std::to_string(number) + ": a second LUCENT_MODULE (the " +
                        "first, '" + name + "', is on line " + std::to_string(first_line) +
                        "); one header declares one module");
        name = m[1].str();
        first_line = number;
    }
    if (name.empty())
        throw Error(file + " declares no module; add LUCENT_MODULE(name) in the namespace of "
                    "its programs (lucent/device/module.h)");
    return name;
}

}  // namespace

ModuleSource ModuleSource::from_text(const std::string& name, const std::string& text,
                                     const std::vector<std::string>& include_dirs) {
    ModuleSource source;
    const fs::path main = fs::absolute(name).lexically_normal();
    source.module = declared_module(main.string(), text);
    Collector(source, include_dirs).add(main, text);
    source.main = source.files.front().first;
    return source;
}

ModuleSource ModuleSource::from_file(const std::string& path,
                                     const std::vector<std::string>& include_dirs) {
    return from_text(path, read_text(path, ""), include_dirs);
}

std::vector<std::string> ModuleSource::paths() const {
    std::vector<std::string> list;
    for (auto& [name, text] : files) list.push_back(name);
    return list;
}

}  // namespace lucent

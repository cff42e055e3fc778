#include "cuda/jit/ptx_calls.h"

#include <cctype>

namespace lucent::cuda {

namespace {

bool is_name_char(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '$' || c == '.';
}

/// The identifiers of one line of PTX (names, directives, registers alike).
std::vector<std::string_view> words(std::string_view line) {
    std::vector<std::string_view> out;
    size_t i = 0;
    while (i < line.size()) {
        if (!is_name_char(line[i])) {
            ++i;
            continue;
        }
        const size_t start = i;
        while (i < line.size() && is_name_char(line[i])) ++i;
        out.push_back(line.substr(start, i - start));
    }
    return out;
}

/// The function a header line names: `.func (.param .b32 r) name(`, `.visible .entry name(`
/// or `.func name`, the last word before the parameter list. Empty for other lines.
std::string header_name(std::string_view line) {
    const std::vector<std::string_view> w = words(line);
    bool function = false;
    for (std::string_view x : w) function = function || x == ".func" || x == ".entry";
    if (!function) return "";
    // A return parameter list comes first in parentheses: skip it.
    size_t from = 0;
    const size_t func = line.find(".func");
    if (func != std::string_view::npos) {
        size_t i = func + 5;
        while (i < line.size() && line[i] == ' ') ++i;
        if (i < line.size() && line[i] == '(') {
            const size_t close = line.find(')', i);
            if (close == std::string_view::npos) return "";
            from = close + 1;
        }
    }
    std::string_view rest = line.substr(from);
    const size_t paren = rest.find('(');
    if (paren != std::string_view::npos) rest = rest.substr(0, paren);
    const std::vector<std::string_view> names = words(rest);
    for (auto it = names.rbegin(); it != names.rend(); ++it)
        if (!it->empty() && it->front() != '.') return std::string(*it);
    return "";
}

}  // namespace

PtxCallGraph ptx_call_graph(std::string_view ptx) {
    // First pass: each function's body, the lines between a header's `{` and its `}` at
    // the start of a line (PTX nests braces inside bodies, indented).
    struct Body {
        std::string name;
        std::vector<std::string_view> lines;
    };
    std::vector<Body> bodies;
    std::string pending;  // a header seen, its body or `;` not yet
    bool in_body = false;
    size_t pos = 0;
    while (pos <= ptx.size()) {
        size_t end = ptx.find('\n', pos);
        if (end == std::string_view::npos) end = ptx.size();
        std::string_view line = ptx.substr(pos, end - pos);
        pos = end + 1;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        if (in_body) {
            if (!line.empty() && line.front() == '}') {
                in_body = false;
                continue;
            }
            bodies.back().lines.push_back(line);
            continue;
        }
        if (line.starts_with("//")) continue;
        if (const std::string name = header_name(line); !name.empty() &&
                                                        line.find(".extern") == line.npos) {
            pending = name;
            if (line.find(';') != line.npos) pending.clear();  // a one-line prototype
            continue;
        }
        if (pending.empty()) continue;
        if (!line.empty() && line.front() == '{') {
            bodies.push_back({pending, {}});
            pending.clear();
            in_body = true;
        } else if (line.find(';') != line.npos) {
            pending.clear();  // the prototype's parameter list ended: no body
        }
    }
    PtxCallGraph graph;
    for (const Body& b : bodies) graph[b.name];
    // Second pass: the defined functions each body names.
    for (const Body& b : bodies) {
        std::set<std::string>& calls = graph[b.name];
        for (std::string_view line : b.lines)
            for (std::string_view w : words(line))
                if (auto it = graph.find(std::string(w)); it != graph.end())
                    calls.insert(it->first);
    }
    return graph;
}

std::vector<std::string> recursive_functions(const PtxCallGraph& graph) {
    std::vector<std::string> out;
    for (const auto& [name, calls] : graph) {
        // Depth-first from the function's callees: is it reached again?
        std::set<std::string> seen;
        std::vector<std::string> todo(calls.begin(), calls.end());
        bool cycle = false;
        while (!todo.empty() && !cycle) {
            const std::string f = todo.back();
            todo.pop_back();
            if (f == name) cycle = true;
            if (!seen.insert(f).second) continue;
            if (auto it = graph.find(f); it != graph.end())
                todo.insert(todo.end(), it->second.begin(), it->second.end());
        }
        if (cycle) out.push_back(name);
    }
    return out;
}

}  // namespace lucent::cuda

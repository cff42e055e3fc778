#include "scene/obj_reader.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string_view>
#include <vector>

#include "lucent/error.h"
#include "scene/input_file.h"
#include "scene/line_reader.h"
#include "scene/progress_stream.h"

namespace lucent::scene {

size_t line_of_statement(const std::string& path, const char* tag, size_t n) {
    std::ifstream in(path);
    std::string line;
    size_t line_no = 0, seen = 0;
    const size_t len = std::char_traits<char>::length(tag);
    while (std::getline(in, line)) {
        ++line_no;
        size_t s = line.find_first_not_of(" \t");
        if (s == std::string::npos || line.compare(s, len, tag) != 0) continue;
        if (s + len < line.size() && line[s + len] != ' ' && line[s + len] != '\t') continue;
        if (seen++ == n) return line_no;
    }
    return 0;
}

/// tinyobjloader reads "nan" or garbage as 0 and wraps face indices past 32 bits, so the
/// numbers it would read are checked here first, with their line numbers.
namespace {

/// The statement's keyword and the rest of the line, or false for blank and comment lines.
bool statement(const std::string& line, std::string& keyword, const char*& rest) {
    const size_t s = line.find_first_not_of(" \t");
    if (s == std::string::npos || line[s] == '#') return false;
    const size_t e = line.find_first_of(" \t", s);
    keyword = line.substr(s, e == std::string::npos ? std::string::npos : e - s);
    rest = line.c_str() + (e == std::string::npos ? line.size() : e);
    return true;
}

std::string trimmed(const std::string& line) {
    const size_t s = line.find_first_not_of(" \t"), e = line.find_last_not_of(" \t\r");
    return s == std::string::npos ? "" : line.substr(s, e - s + 1);
}

/// `count` finite numbers (at least `needed`) after the keyword.
void check_numbers(const std::string& path, size_t line_no, const std::string& line,
                   const char* rest, int needed, int count, const std::string& what) {
    const char* p = rest;
    const char* const line_end = line.c_str() + line.size();
    for (int k = 0; k < count; ++k) {
        // std::from_chars: strtof's locale look-ups were its time in a 1 GB file.
        while (*p == ' ' || *p == '\t') ++p;
        if (*p == '+') ++p;
        float x = 0;
        const auto [end, error] = std::from_chars(p, line_end, x);
        // Out of range: strtof's reading, infinite for "1e39" (refused), 0 for "1e-50".
        if (error == std::errc::result_out_of_range) x = std::strtof(p, nullptr);
        if (error == std::errc::invalid_argument) {
            if (k >= needed) return;  // the optional ones may be left out
            fail(path, line_no, what + " needs " + std::to_string(needed) + " numbers: '" +
                                    trimmed(line) + "'");
        }
        if (!std::isfinite(x))
            fail(path, line_no, what + " has a value that is not a finite number: '" +
                                    trimmed(line) + "'");
        p = end;
    }
}

/// Each v/vt/vn reference of a face: an integer (negative: relative) tinyobjloader's int
/// holds, so nothing wraps around to another vertex.
void check_face(const std::string& path, size_t line_no, const std::string& line, const char* rest) {
    const char* p = rest;
    for (;;) {
        while (*p == ' ' || *p == '\t' || *p == '\r') ++p;
        if (!*p) return;
        const char* word = p;
        while (*p && *p != ' ' && *p != '\t' && *p != '\r') ++p;
        const std::string_view w(word, size_t(p - word));
        size_t start = 0;
        for (int part = 0; part < 3 && start <= w.size(); ++part) {
            const size_t slash = w.find('/', start);
            const std::string_view index =
                w.substr(start, slash == std::string_view::npos ? std::string_view::npos
                                                                : slash - start);
            start = slash == std::string_view::npos ? w.size() + 1 : slash + 1;
            if (index.empty() && part > 0) continue;  // "1//3": no texture coordinate
            const size_t first = !index.empty() && index[0] == '-' ? 1 : 0;
            bool digits = index.size() > first && index.size() <= 11;
            long long value = 0;
            for (size_t k = first; digits && k < index.size(); ++k) {
                digits = index[k] >= '0' && index[k] <= '9';
                value = value * 10 + (index[k] - '0');
            }
            if (!digits || value > 2147483647LL)
                fail(path, line_no, "face index '" + std::string(index) + "' in '" +
                                        std::string(w) +
                                        "' is not an integer in -2147483647..2147483647: '" +
                                        trimmed(line) + "'");
        }
    }
}

/// Every line of the OBJ once: its numbers, and the MTL files it names (with their lines).
void check_obj_numbers(const std::string& path, const LoadProgress& progress,
                       std::vector<std::pair<std::string, size_t>>& mtl_files) {
    LineReader in(path, "OBJ file", progress,
                  "checking " + std::filesystem::path(path).filename().string());
    std::string line, keyword;
    const char* rest = nullptr;
    size_t vertex = 0;
    while (in.next(line)) {
        const size_t line_no = in.line_number();
        if (!statement(line, keyword, rest)) continue;
        if (keyword == "v") {
            ++vertex;
            check_numbers(path, line_no, line, rest, 3, 3, "vertex " + std::to_string(vertex));
        } else if (keyword == "vn") {
            check_numbers(path, line_no, line, rest, 3, 3, "normal");
        } else if (keyword == "vt") {
            check_numbers(path, line_no, line, rest, 1, 3, "texture coordinate");
        } else if (keyword == "f") {
            check_face(path, line_no, line, rest);
        } else if (keyword == "mtllib") {
            std::string name = rest;
            name.erase(0, name.find_first_not_of(" \t"));
            while (!name.empty() && (name.back() == '\r' || name.back() == ' ')) name.pop_back();
            const std::filesystem::path dir = std::filesystem::path(path).parent_path();
            mtl_files.emplace_back((dir / name).string(), line_no);
        }
    }
}

/// The numbers of an MTL's colours and scalars (tinyobjloader reads "nan" as a number).
void check_mtl_numbers(const std::string& path) {
    if (!std::filesystem::exists(path)) return;  // a missing MTL is tinyobjloader's warning
    static const char* const kColours[] = {"Ka", "Kd", "Ks", "Ke", "Tf"};
    static const char* const kScalars[] = {"Ns", "Ni", "d", "Tr"};
    LineReader in(path, "MTL file");
    std::string line, keyword;
    const char* rest = nullptr;
    while (in.next(line)) {
        const size_t line_no = in.line_number();
        if (!statement(line, keyword, rest)) continue;
        for (const char* k : kColours)
            if (keyword == k) check_numbers(path, line_no, line, rest, 1, 3, keyword);
        for (const char* k : kScalars)
            if (keyword == k) check_numbers(path, line_no, line, rest, 1, 1, keyword);
    }
}

}  // namespace

void fail(const std::string& path, size_t line, const std::string& message) {
    throw Error(path + ":" + std::to_string(line) + ": " + message);
}

ObjData read_obj(const std::string& path, bool with_materials, const LoadProgress& progress) {
    require_regular_file(path, "OBJ file");
    ObjData obj;
    check_obj_numbers(path, progress, obj.mtllibs);  // throws "path:0: cannot open" first
    // tinyobjloader names an MTL relative to this folder; "/nonexistent/" reads none.
    const std::string folder = std::filesystem::path(path).parent_path().string();
    const std::string mtl_folder = !with_materials ? "/nonexistent/"
                                   : folder.empty() ? "./"
                                                    : folder + "/";
    if (with_materials)
        for (const auto& [mtl, line] : obj.mtllibs) {
            require_regular_file(mtl, "MTL file");
            check_mtl_numbers(mtl);
        }
    ProgressStreambuf buffer(path, progress,
                             "reading " + std::filesystem::path(path).filename().string());
    if (!buffer.is_open()) fail(path, 0, "cannot open the OBJ file (check the path)");
    std::istream in(&buffer);
    tinyobj::MaterialFileReader materials(mtl_folder);
    std::string warn, err;
    // Not triangulated: fanned by the callers, so a face maps back to its line.
    const bool ok = tinyobj::LoadObj(&obj.attrib, &obj.shapes, &obj.materials, &warn, &err, &in,
                                     &materials, /*triangulate=*/false,
                                     /*default_vcols_fallback=*/false);
    if (!ok) {
        while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
        std::smatch m;
        size_t line = 0;
        if (std::regex_search(err, m, std::regex("line (\\d+)"))) line = std::stoul(m[1]);
        fail(path, line, "cannot parse OBJ: " + err);
    }
    return obj;
}

}  // namespace lucent::scene

#include "scene/obj_reader.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <vector>

#include "lucent/error.h"
#include "scene/input_file.h"

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
    for (int k = 0; k < count; ++k) {
        char* end = nullptr;
        const float x = std::strtof(p, &end);
        if (end == p) {
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
    std::istringstream words(rest);
    for (std::string word; words >> word;) {
        size_t start = 0;
        for (int part = 0; part < 3 && start <= word.size(); ++part) {
            const size_t slash = word.find('/', start);
            const std::string index = word.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
            start = slash == std::string::npos ? word.size() + 1 : slash + 1;
            if (index.empty() && part > 0) continue;  // "1//3": no texture coordinate
            const bool digits = !index.empty() &&
                                index.find_first_not_of("0123456789", index[0] == '-' ? 1 : 0) == std::string::npos &&
                                index != "-";
            if (!digits || index.size() > 11 || std::llabs(std::atoll(index.c_str())) > 2147483647LL)
                fail(path, line_no, "face index '" + index + "' in '" + word +
                                        "' is not an integer in -2147483647..2147483647: '" +
                                        trimmed(line) + "'");
        }
    }
}

void check_obj_numbers(const std::string& path, std::vector<std::string>& mtl_files) {
    std::ifstream in(path);
    std::string line, keyword;
    const char* rest = nullptr;
    size_t line_no = 0, vertex = 0;
    while (std::getline(in, line)) {
        ++line_no;
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
            std::istringstream names(rest);
            for (std::string name; names >> name;) mtl_files.push_back(name);
        }
    }
}

/// The numbers of an MTL's colours and scalars (tinyobjloader reads "nan" as a number).
void check_mtl_numbers(const std::string& path) {
    std::ifstream in(path);
    if (!in) return;  // a missing MTL is tinyobjloader's warning, as before
    static const char* const kColours[] = {"Ka", "Kd", "Ks", "Ke", "Tf"};
    static const char* const kScalars[] = {"Ns", "Ni", "d", "Tr"};
    std::string line, keyword;
    const char* rest = nullptr;
    size_t line_no = 0;
    while (std::getline(in, line)) {
        ++line_no;
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

tinyobj::ObjReader read_obj(const std::string& path, bool with_materials) {
    require_regular_file(path, "OBJ file");
    {
        std::ifstream probe(path);
        if (!probe) fail(path, 0, "cannot open the OBJ file (check the path)");
    }
    std::vector<std::string> mtl_files;
    check_obj_numbers(path, mtl_files);
    tinyobj::ObjReaderConfig config;
    config.triangulate = false;  // fanned by the callers, so a face maps back to its line
    config.vertex_color = false;
    if (with_materials) {
        size_t slash = path.find_last_of('/');
        config.mtl_search_path = slash == std::string::npos ? "./" : path.substr(0, slash + 1);
        for (const std::string& name : mtl_files) {
            const std::string mtl = config.mtl_search_path + name;
            require_regular_file(mtl, "MTL file");
            check_mtl_numbers(mtl);
        }
    } else {
        config.mtl_search_path = "/nonexistent/";  // geometry only: no MTL is read
    }
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path, config)) {
        std::string err = reader.Error();
        while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
        std::smatch m;
        size_t line = 0;
        if (std::regex_search(err, m, std::regex("line (\\d+)"))) line = std::stoul(m[1]);
        fail(path, line, "cannot parse OBJ: " + err);
    }
    return reader;
}

}  // namespace lucent::scene

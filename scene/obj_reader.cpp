#include "scene/obj_reader.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <regex>

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

/// tinyobjloader reads "nan" or garbage as 0, so vertex coordinates are checked here,
/// with their line numbers.
namespace {
void check_vertices(const std::string& path) {
    std::ifstream in(path);
    std::string line;
    size_t line_no = 0, vertex = 0;
    while (std::getline(in, line)) {
        ++line_no;
        size_t s = line.find_first_not_of(" \t");
        if (s == std::string::npos || line[s] != 'v' || s + 1 >= line.size() ||
            (line[s + 1] != ' ' && line[s + 1] != '\t'))
            continue;
        ++vertex;
        const char* p = line.c_str() + s + 1;
        for (int k = 0; k < 3; ++k) {
            char* end = nullptr;
            float x = std::strtof(p, &end);
            if (end == p || !std::isfinite(x))
                fail(path, line_no,
                     "vertex " + std::to_string(vertex) +
                         " has a coordinate that is not a finite "
                         "number: '" +
                         line.substr(s) + "'");
            p = end;
        }
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
    check_vertices(path);
    tinyobj::ObjReaderConfig config;
    config.triangulate = false;  // fanned by the callers, so a face maps back to its line
    config.vertex_color = false;
    if (with_materials) {
        size_t slash = path.find_last_of('/');
        config.mtl_search_path = slash == std::string::npos ? "./" : path.substr(0, slash + 1);
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

// Reading an OBJ (and its MTL) with tinyobjloader, with every error pointing at its file
// and line: tinyobjloader reads "nan" or garbage coordinates as 0 and reports few lines, so
// coordinates are checked here first and statements are mapped back to their lines.
#pragma once

#include <tiny_obj_loader.h>

#include <string>
#include <utility>
#include <vector>

#include "scene/load_progress.h"

namespace lucent::scene {

/// What tinyobjloader read, and the MTL files the OBJ names with the line of each.
struct ObjData {
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::vector<std::pair<std::string, size_t>> mtllibs;  // paths beside the OBJ, and lines
};

/// Parses `path` (and, when asked, the MTL files it names), in two passes over the file:
/// one that checks every line (text, numbers that are numbers, indices that fit), then
/// tinyobjloader's, each reported to `progress`. Throws lucent::Error "path:line: message"
/// for a missing file, a non-finite coordinate or a parse error.
ObjData read_obj(const std::string& path, bool with_materials, const LoadProgress& progress = {});

/// 1-based line of the n-th (0-based) statement starting with `tag` ("v" or "f"), or 0.
size_t line_of_statement(const std::string& path, const char* tag, size_t n);

/// Throws lucent::Error "path:line: message".
[[noreturn]] void fail(const std::string& path, size_t line, const std::string& message);

}  // namespace lucent::scene

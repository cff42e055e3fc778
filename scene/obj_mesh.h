// Triangle meshes from Wavefront OBJ files (positions and faces only), via tinyobjloader.
#pragma once

#include <string>
#include <vector>

#include "lucent/device/vector_math.h"

namespace lucent::scene {

/// Positions and triangles (polygons are fanned into triangles, in file order).
struct ObjMesh {
    std::vector<float3> positions;
    std::vector<uint3> indices;
};

/// Loads the geometry of an OBJ file. Throws lucent::Error "file:line: message" for a
/// missing or unreadable file, a parse error, a non-finite vertex, a face index out of
/// range, or a file without triangles.
ObjMesh load_obj_mesh(const std::string& path);

}  // namespace lucent::scene

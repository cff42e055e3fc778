// The triangles of a triangles-only GeometryGroup as one mesh: every instance's vertices
// concatenated and its indices rebased onto them. The CPU's TriangleAccel is built over this
// mesh; a GPU build gathers the same mesh on the device from the buffers' device copies
// (GpuScene), so for it the host computes only the group's bounds.
#pragma once

#include <cstdint>
#include <vector>

#include "core/compiled_scene.h"

namespace lucent::core {

/// A triangles-only group's triangles in one mesh. `tri_instance`, if given, gets each
/// triangle's position in node.instances.
void gather_triangles(const CompiledScene& scene, const CompiledNode& node,
                      std::vector<float3>& vertices, std::vector<uint3>& indices,
                      std::vector<uint32_t>* tri_instance = nullptr);

/// The box of a triangles-only group's triangles (of the vertices they use), without
/// gathering them; empty (lo > hi) when there are none.
Aabb triangle_bounds(const CompiledScene& scene, const CompiledNode& node);

}  // namespace lucent::core

// The built-in primitives' buffers, checked and bound into a CompiledInstance: triangles
// (vertices, indices), spheres (centres, radii) and curves (vertices, radii, segments), with their per-primitive material
// indices. Every index and value the traversal will read is checked here, once per
// compile, so a bad buffer is an Error naming the geometry and the primitive, never a read
// out of bounds or a NaN box in a BVH.
#pragma once

#include "core/compiled_scene.h"

namespace lucent::core {

void bind_triangles(const GeometryTriangles& triangles, const GeometryInstance& instance,
                    CompiledInstance& out);
void bind_spheres(const GeometrySpheres& spheres, const GeometryInstance& instance,
                  CompiledInstance& out);
void bind_curves(const GeometryCurves& curves, const GeometryInstance& instance,
                 CompiledInstance& out);

}  // namespace lucent::core

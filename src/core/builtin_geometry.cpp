#include "core/builtin_geometry.h"

#include <algorithm>
#include <cmath>

#include "lucent/error.h"

namespace lucent::core {

namespace {

/// The largest of `count` values (0 for none), as vector code: 16 running maxima over the
/// flat array where one would be a chain of dependent steps. Validation reads every index of
/// a mesh at each compile (Sponza: 200K vertex and 66K material indices); a range check per
/// value, with a branch, took a third of Sponza's scene compile (median 0.57 ms, now 0.44,
/// on the development machine). The first index out of range is looked for only when the
/// largest is.
unsigned largest_of(const unsigned* values, size_t count) {
    constexpr size_t kStep = 16;
    unsigned step_max[kStep] = {};
    const size_t whole = count / kStep * kStep;
    for (size_t i = 0; i < whole; i += kStep)
        for (size_t j = 0; j < kStep; ++j)
            step_max[j] = values[i + j] > step_max[j] ? values[i + j] : step_max[j];
    unsigned largest = 0;
    for (size_t j = 0; j < kStep; ++j) largest = std::max(largest, step_max[j]);
    for (size_t i = whole; i < count; ++i) largest = std::max(largest, values[i]);
    return largest;
}

/// The optional per-primitive material indices: one per primitive, each below the
/// instance's material count.
const unsigned* bind_material_indices(const GeometryBase& geometry,
                                      const std::shared_ptr<Buffer>& buffer,
                                      const GeometryInstance& instance, unsigned count,
                                      const char* primitive) {
    if (!buffer) return nullptr;
    if (buffer->count() != count)
        throw Error(geometry.describe() + ": the material index buffer has " +
                    std::to_string(buffer->count()) + " entries for " + std::to_string(count) +
                    " " + primitive + "s; give one per " + primitive);
    const unsigned* indices = buffer->data<unsigned>();
    if (count == 0 || largest_of(indices, count) < instance.material_count()) return indices;
    for (unsigned i = 0; i < count; ++i)  // the first index out of range, for the message
        if (indices[i] >= instance.material_count())
            throw Error(geometry.describe() + ": " + primitive + " " + std::to_string(i) +
                        " selects material " + std::to_string(indices[i]) + " but " +
                        instance.describe() + " has " +
                        std::to_string(instance.material_count()) +
                        "; add materials or fix the index");
    return indices;
}

bool finite(float3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

void bind_triangles(const GeometryTriangles& tris, const GeometryInstance& instance,
                    CompiledInstance& out) {
    if (!tris.vertices())
        throw Error(tris.describe() + " has no vertex buffer; set one with set_vertices");
    out.vertices = tris.vertices()->data<float3>();
    const size_t vertex_count = tris.vertices()->count();
    if (tris.indices()) {
        out.indices = static_cast<const uint3*>(tris.indices()->raw());
        static_assert(sizeof(uint3) == 3 * sizeof(unsigned), "uint3 must be three packed values");
        const bool in_range =
            out.primitive_count == 0 ||
            largest_of(&out.indices[0].x, 3 * size_t(out.primitive_count)) < vertex_count;
        // The first triangle out of range, for the message.
        for (unsigned i = 0; !in_range && i < out.primitive_count; ++i) {
            const uint3 t = out.indices[i];
            if (t.x >= vertex_count || t.y >= vertex_count || t.z >= vertex_count)
                throw Error(tris.describe() + ": triangle " + std::to_string(i) +
                            " uses vertex " + std::to_string(std::max({t.x, t.y, t.z})) +
                            " but there are " + std::to_string(vertex_count) +
                            " vertices; fix the index buffer");
        }
    } else if (vertex_count % 3 != 0) {
        throw Error(tris.describe() +
                    ": without an index buffer the vertex count must be a multiple of 3, got " +
                    std::to_string(vertex_count));
    }
    out.material_indices = bind_material_indices(tris, tris.material_indices(), instance,
                                                 out.primitive_count, "triangle");
}

void bind_spheres(const GeometrySpheres& spheres, const GeometryInstance& instance,
                  CompiledInstance& out) {
    if (!spheres.centers())
        throw Error(spheres.describe() + " has no centre buffer; set one with set_centers");
    if (!spheres.radii())
        throw Error(spheres.describe() + " has no radius buffer; set one with set_radii");
    const unsigned count = out.primitive_count;
    const size_t radius_count = spheres.radii()->count();
    if (radius_count != 1 && radius_count != count)
        throw Error(spheres.describe() + ": the radius buffer has " +
                    std::to_string(radius_count) + " entries for " + std::to_string(count) +
                    " spheres; give one per sphere, or one for all");
    out.centers = spheres.centers()->data<float3>();
    out.radii = spheres.radii()->data<float>();
    out.single_radius = radius_count == 1 && count != 1;
    for (unsigned i = 0; i < count; ++i) {
        const float r = out.radii[out.single_radius ? 0 : i];
        if (!finite(out.centers[i]))
            throw Error(spheres.describe() + ": sphere " + std::to_string(i) +
                        " has a centre that is not finite; fix the centre buffer");
        if (!(r >= 0.0f) || !std::isfinite(r))
            throw Error(spheres.describe() + ": sphere " + std::to_string(i) + " has radius " +
                        std::to_string(r) + "; radii must be finite and at least 0");
    }
    out.material_indices = bind_material_indices(spheres, spheres.material_indices(), instance,
                                                 count, "sphere");
}

void bind_curves(const GeometryCurves& curves, const GeometryInstance& instance,
                 CompiledInstance& out) {
    if (!curves.vertices())
        throw Error(curves.describe() + " has no vertex buffer; set one with set_vertices");
    if (!curves.radii())
        throw Error(curves.describe() + " has no radius buffer; set one with set_radii");
    if (!curves.segment_indices())
        throw Error(curves.describe() +
                    " has no segment index buffer; set one with set_segment_indices");
    const size_t vertex_count = curves.vertices()->count();
    if (curves.radii()->count() != vertex_count)
        throw Error(curves.describe() + ": the radius buffer has " +
                    std::to_string(curves.radii()->count()) + " entries for " +
                    std::to_string(vertex_count) + " vertices; give one radius per vertex");
    out.vertices = curves.vertices()->data<float3>();
    out.radii = curves.radii()->data<float>();
    out.segments = curves.segment_indices()->data<unsigned>();
    out.curve_type = curves.curve_type();
    for (size_t i = 0; i < vertex_count; ++i) {
        const float r = out.radii[i];
        if (!finite(out.vertices[i]))
            throw Error(curves.describe() + ": vertex " + std::to_string(i) +
                        " is not finite; fix the vertex buffer");
        if (!(r >= 0.0f) || !std::isfinite(r))
            throw Error(curves.describe() + ": vertex " + std::to_string(i) + " has radius " +
                        std::to_string(r) + "; radii must be finite and at least 0");
    }
    const unsigned points = curve_control_points(out.curve_type);
    for (unsigned i = 0; i < out.primitive_count; ++i)
        if (size_t(out.segments[i]) + points > vertex_count)
            throw Error(curves.describe() + ": segment " + std::to_string(i) + " starts at vertex " +
                        std::to_string(out.segments[i]) + " and needs " + std::to_string(points) +
                        " control points, but there are " + std::to_string(vertex_count) +
                        " vertices; fix the segment index buffer");
    out.material_indices = bind_material_indices(curves, curves.material_indices(), instance,
                                                 out.primitive_count, "segment");
}

}  // namespace lucent::core

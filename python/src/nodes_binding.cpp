// The node graph from Python: Group, GeometryGroup, Transform, Selector, GeometryInstance,
// Geometry, GeometryTriangles, Material, Acceleration and TextureSampler, as the C++ API
// has them (lucent/nodes.h); a Context creates each (context_binding.cpp).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>

#include "array_args.h"
#include "bindings.h"

namespace lucent::python {

namespace {

Builder builder_from(const std::string& name) {
    if (name == "auto") return Builder::kAuto;
    if (name == "sah") return Builder::kBinnedSah;
    if (name == "none") return Builder::kNone;
    if (name == "gpu_hploc") return Builder::kGpuHploc;
    throw py::value_error("builder: expected 'auto', 'sah', 'none' or 'gpu_hploc'; got '" + name +
                          "'");
}

const char* builder_name(Builder b) {
    switch (b) {
        case Builder::kAuto: return "auto";
        case Builder::kBinnedSah: return "sah";
        case Builder::kNone: return "none";
        case Builder::kGpuHploc: return "gpu_hploc";
    }
    return "?";
}

WrapMode wrap_from(const std::string& name) {
    if (name == "repeat") return WrapMode::kRepeat;
    if (name == "clamp") return WrapMode::kClampToEdge;
    if (name == "mirror") return WrapMode::kMirror;
    throw py::value_error("wrap mode: expected 'repeat', 'clamp' or 'mirror'; got '" + name + "'");
}

template <class T>
std::string repr(const T& object) {
    return "<lucent." + object.describe() + ">";
}

}  // namespace

Builder builder_from_name(const std::string& name) {
    return builder_from(name);
}

void bind_nodes(py::module_& m) {
    py::class_<Acceleration, std::shared_ptr<Acceleration>>(m, "Acceleration",
                                                            "The BVH of a Group or GeometryGroup.")
        .def_property("builder", [](const Acceleration& a) { return builder_name(a.builder()); },
                      [](Acceleration& a, const std::string& b) { a.set_builder(builder_from(b)); },
                      "'auto' (the default: binned SAH, built on the GPU by the CUDA backend), "
                      "'sah' (binned SAH built on the host), 'none' (every child tested) or "
                      "'gpu_hploc' (H-PLOC, built on the GPU by the CUDA backend)")
        .def_property("refit", &Acceleration::refit, &Acceleration::set_refit,
                      "Refit instead of rebuilding when only vertices moved")
        .def("mark_dirty", &Acceleration::mark_dirty)
        .def("__repr__", [](const Acceleration& a) { return repr(a); });

    py::class_<TextureSampler, std::shared_ptr<TextureSampler>>(m, "TextureSampler")
        .def_property("buffer", &TextureSampler::buffer, &TextureSampler::set_buffer,
                      "A 2D float4 Buffer of texels")
        .def("set_wrap_mode", [](TextureSampler& t, const std::string& u, const std::string& v) {
            t.set_wrap_mode(wrap_from(u), wrap_from(v));
        })
        .def("set_filter", [](TextureSampler& t, const std::string& f) {
            if (f != "nearest" && f != "linear")
                throw py::value_error("filter: expected 'nearest' or 'linear'; got '" + f + "'");
            t.set_filter(f == "nearest" ? FilterMode::kNearest : FilterMode::kLinear);
        })
        .def("__repr__", [](const TextureSampler& t) { return repr(t); });

    // The device API's constants, for records and for Python code that builds flags.
    m.attr("MOTION_FLAG_NONE") = unsigned(kMotionFlagNone);
    m.attr("MOTION_FLAG_START_VANISH") = unsigned(kMotionFlagStartVanish);
    m.attr("MOTION_FLAG_END_VANISH") = unsigned(kMotionFlagEndVanish);
    m.attr("GEOMETRY_FLAG_NONE") = unsigned(kGeometryFlagNone);
    m.attr("GEOMETRY_FLAG_DISABLE_ANYHIT") = unsigned(kGeometryFlagDisableAnyHit);
    m.attr("VISIBILITY_MASK_ALL") = kVisibilityMaskAll;
    m.attr("CURVE_LINEAR") = unsigned(kCurveLinear);
    m.attr("CURVE_QUADRATIC_BSPLINE") = unsigned(kCurveQuadraticBSpline);
    m.attr("CURVE_CUBIC_BSPLINE") = unsigned(kCurveCubicBSpline);
    m.attr("CURVE_CATMULL_ROM") = unsigned(kCurveCatmullRom);
    m.attr("RAY_FLAG_NONE") = unsigned(kRayFlagNone);
    m.attr("RAY_FLAG_DISABLE_ANYHIT") = unsigned(kRayFlagDisableAnyHit);
    m.attr("RAY_FLAG_ENFORCE_ANYHIT") = unsigned(kRayFlagEnforceAnyHit);
    m.attr("RAY_FLAG_TERMINATE_ON_FIRST_HIT") = unsigned(kRayFlagTerminateOnFirstHit);
    m.attr("RAY_FLAG_DISABLE_CLOSESTHIT") = unsigned(kRayFlagDisableClosestHit);
    m.attr("RAY_FLAG_CULL_BACK_FACING_TRIANGLES") = unsigned(kRayFlagCullBackFacingTriangles);
    m.attr("RAY_FLAG_CULL_FRONT_FACING_TRIANGLES") = unsigned(kRayFlagCullFrontFacingTriangles);
    m.attr("RAY_FLAG_CULL_DISABLED_ANYHIT") = unsigned(kRayFlagCullDisabledAnyHit);
    m.attr("RAY_FLAG_CULL_ENFORCED_ANYHIT") = unsigned(kRayFlagCullEnforcedAnyHit);

    py::class_<Node, std::shared_ptr<Node>>(m, "Node", "A node of the scene graph.")
        .def_property("name", [](const Node& n) { return n.name(); }, &Node::set_name)
        .def_property_readonly("kind", [](const Node& n) { return std::string(node_kind_name(n.kind())); })
        .def_property("visibility_mask", &Node::visibility_mask, &Node::set_visibility_mask,
                      "8-bit mask (default 0xff): rays whose visibility mask shares no bit with "
                      "it skip the node and everything below it")
        .def("__repr__", [](const Node& n) { return repr(n); });

    py::class_<NodeWithChildren, Node, std::shared_ptr<NodeWithChildren>>(m, "NodeWithChildren")
        .def("add_child", &NodeWithChildren::add_child, py::arg("child"),
             "Appends a child node; returns its index.")
        .def("set_child", &NodeWithChildren::set_child)
        .def("remove_child", &NodeWithChildren::remove_child)
        .def_property_readonly("child_count", &NodeWithChildren::child_count)
        .def("child", &NodeWithChildren::child)
        .def_property_readonly("children", &NodeWithChildren::children);

    py::class_<Group, NodeWithChildren, std::shared_ptr<Group>>(
        m, "Group", "Children of any node kind under an acceleration structure.")
        .def_property("acceleration", &Group::acceleration, &Group::set_acceleration);

    py::class_<Selector, NodeWithChildren, std::shared_ptr<Selector>>(
        m, "Selector", "Children chosen per ray by a visit program.")
        .def_property("visit_program", &Selector::visit_program, &Selector::set_visit_program);

    py::class_<Transform, Node, std::shared_ptr<Transform>>(
        m, "Transform", "One child moved by an affine 3x4 matrix (object to world).")
        .def_property("child", &Transform::child, &Transform::set_child)
        .def_property(
            "matrix",
            [](const Transform& t) {
                py::array_t<float> a({3, 4});
                std::memcpy(a.mutable_data(), t.matrix().m, 12 * sizeof(float));
                return a;
            },
            [](Transform& t, const py::handle& value) {
                py::ssize_t unused = 0;
                // A (4, 4) matrix's last row must be 0 0 0 1: take the (3, 4) part.
                py::array a = py::module_::import("numpy").attr("asarray")(value);
                if (a.ndim() == 2 && a.shape(0) == 4 && a.shape(1) == 4)
                    a = a.attr("__getitem__")(py::slice(0, 3, 1));
                py::array_t<float> m = float32_array(
                    py::module_::import("numpy").attr("ascontiguousarray")(a), "Transform.matrix",
                    "matrix", {3, 4}, "", unused);
                t.set_matrix(m.data());
            },
            "Row-major (3, 4) float32 (a (4, 4) matrix gives its top three rows)")
        .def_property("instance_id", &Transform::instance_id, &Transform::set_instance_id,
                      "User id that hit programs below read with instance_id() (default 0)")
        .def(
            "set_motion_matrices",
            [](Transform& t, const py::handle& keys, float time_begin, float time_end,
               unsigned flags) {
                py::ssize_t count = 0;
                py::array_t<float> a = float32_array(keys, "Transform.set_motion_matrices", "keys",
                                                     {-1, 3, 4}, "K", count);
                std::vector<Matrix4x3> m(static_cast<size_t>(count));
                std::memcpy(m.data(), a.data(), m.size() * sizeof(Matrix4x3));
                t.set_motion_matrices(m, MotionOptions{time_begin, time_end, flags});
            },
            py::arg("keys"), py::arg("time_begin") = 0.0f, py::arg("time_end") = 1.0f,
            py::arg("flags") = unsigned(kMotionFlagNone),
            "Matrix motion: (K, 3, 4) float32 object-to-world keys, K >= 2, spaced evenly over "
            "[time_begin, time_end]; MOTION_FLAG_* say whether the child vanishes outside it")
        .def(
            "set_motion_srt",
            [](Transform& t, const py::handle& keys, float time_begin, float time_end,
               unsigned flags) {
                py::ssize_t count = 0;
                py::array_t<float> a =
                    float32_array(keys, "Transform.set_motion_srt", "keys", {-1, 16}, "K", count);
                std::vector<SrtData> k(static_cast<size_t>(count));
                std::memcpy(k.data(), a.data(), k.size() * sizeof(SrtData));
                t.set_motion_srt(k, MotionOptions{time_begin, time_end, flags});
            },
            py::arg("keys"), py::arg("time_begin") = 0.0f, py::arg("time_end") = 1.0f,
            py::arg("flags") = unsigned(kMotionFlagNone),
            "SRT motion: (K, 16) float32 keys (sx, a, b, pvx, sy, c, pvy, sz, pvz, qx, qy, qz, "
            "qw, tx, ty, tz), K >= 2, as OptiX's OptixSRTData")
        .def_property_readonly("motion_key_count", &Transform::motion_key_count);

    py::class_<GeometryBase, std::shared_ptr<GeometryBase>> geometry_base(m, "GeometryBase");
    geometry_base.def_property_readonly("primitive_count", &GeometryBase::primitive_count)
        .def_property("flags", &GeometryBase::flags, &GeometryBase::set_flags,
                      "GEOMETRY_FLAG_* or'ed: GEOMETRY_FLAG_DISABLE_ANYHIT makes the geometry "
                      "opaque (its any-hit programs never run unless a ray enforces them)")
        .def("__repr__", [](const GeometryBase& g) { return repr(g); });
    add_variable_access(geometry_base);

    py::class_<Geometry, GeometryBase, std::shared_ptr<Geometry>>(
        m, "Geometry", "Custom primitives: a bounding-box and an intersection program.")
        .def_property("primitive_count", &Geometry::primitive_count, &Geometry::set_primitive_count)
        .def_property("bounding_box_program", &Geometry::bounding_box_program,
                      &Geometry::set_bounding_box_program)
        .def_property("intersection_program", &Geometry::intersection_program,
                      &Geometry::set_intersection_program);

    py::class_<GeometryTriangles, GeometryBase, std::shared_ptr<GeometryTriangles>>(
        m, "GeometryTriangles",
        "Built-in triangles: a float3 vertex Buffer, an optional uint3 index Buffer and an "
        "optional uint per-triangle material index Buffer.")
        .def_property("vertices", &GeometryTriangles::vertices, &GeometryTriangles::set_vertices)
        .def_property("indices", &GeometryTriangles::indices, &GeometryTriangles::set_indices)
        .def_property("material_indices", &GeometryTriangles::material_indices,
                      &GeometryTriangles::set_material_indices)
        .def_property("attribute_program", &GeometryTriangles::attribute_program,
                      &GeometryTriangles::set_attribute_program)
        .def(
            "set_motion_vertices",
            [](GeometryTriangles& g, std::vector<std::shared_ptr<Buffer>> keys, float time_begin,
               float time_end, unsigned flags) {
                g.set_motion_vertices(std::move(keys), MotionOptions{time_begin, time_end, flags});
            },
            py::arg("keys"), py::arg("time_begin") = 0.0f, py::arg("time_end") = 1.0f,
            py::arg("flags") = unsigned(kMotionFlagNone),
            "Motion triangles: a list of float3 vertex Buffers, one per key (2 or more, equal "
            "lengths), spaced evenly over [time_begin, time_end]");

    py::class_<GeometrySpheres, GeometryBase, std::shared_ptr<GeometrySpheres>>(
        m, "GeometrySpheres",
        "Built-in spheres: a float3 centre Buffer, a float radius Buffer (one per sphere or one "
        "for all) and an optional uint per-sphere material index Buffer. Hit programs read "
        "BuiltinSphereAttributes (object-space normal, entering).")
        .def_property("centers", &GeometrySpheres::centers, &GeometrySpheres::set_centers)
        .def_property("radii", &GeometrySpheres::radii, &GeometrySpheres::set_radii)
        .def_property("material_indices", &GeometrySpheres::material_indices,
                      &GeometrySpheres::set_material_indices)
        .def(
            "set_motion_centers",
            [](GeometrySpheres& g, std::vector<std::shared_ptr<Buffer>> keys, float time_begin,
               float time_end, unsigned flags) {
                g.set_motion_centers(std::move(keys), MotionOptions{time_begin, time_end, flags});
            },
            py::arg("keys"), py::arg("time_begin") = 0.0f, py::arg("time_end") = 1.0f,
            py::arg("flags") = unsigned(kMotionFlagNone),
            "Moving spheres: a list of float3 centre Buffers, one per key (2 or more, equal "
            "lengths), spaced evenly over [time_begin, time_end]; the radii stay those of radii");

    py::class_<GeometryCurves, GeometryBase, std::shared_ptr<GeometryCurves>>(
        m, "GeometryCurves",
        "Built-in round curves: curve_type (CURVE_LINEAR, CURVE_QUADRATIC_BSPLINE, "
        "CURVE_CUBIC_BSPLINE or CURVE_CATMULL_ROM, default cubic), a float3 vertex Buffer, a "
        "float radius Buffer (one per vertex), a uint segment index Buffer (each segment's "
        "first control point) and an optional uint per-segment material index Buffer. Hit "
        "programs read BuiltinCurveAttributes (object-space normal, u, entering).")
        .def_property(
            "curve_type", [](const GeometryCurves& c) { return unsigned(c.curve_type()); },
            [](GeometryCurves& c, unsigned type) { c.set_curve_type(CurveType(type)); })
        .def_property("vertices", &GeometryCurves::vertices, &GeometryCurves::set_vertices)
        .def_property("radii", &GeometryCurves::radii, &GeometryCurves::set_radii)
        .def_property("segment_indices", &GeometryCurves::segment_indices,
                      &GeometryCurves::set_segment_indices)
        .def_property("material_indices", &GeometryCurves::material_indices,
                      &GeometryCurves::set_material_indices);

    py::class_<Material, std::shared_ptr<Material>> material(
        m, "Material", "Closest-hit and any-hit programs per ray type.");
    material.def("set_closest_hit", &Material::set_closest_hit, py::arg("ray_type"),
                 py::arg("program"))
        .def("set_any_hit", &Material::set_any_hit, py::arg("ray_type"), py::arg("program"))
        .def("closest_hit", &Material::closest_hit)
        .def("any_hit", &Material::any_hit)
        .def("__repr__", [](const Material& x) { return repr(x); });
    add_variable_access(material);

    py::class_<GeometryInstance, std::shared_ptr<GeometryInstance>> instance(
        m, "GeometryInstance", "A geometry bound to its materials.");
    instance.def_property("geometry", &GeometryInstance::geometry, &GeometryInstance::set_geometry)
        .def("add_material", &GeometryInstance::add_material, py::arg("material"),
             "Appends a material; returns its index.")
        .def("set_material", &GeometryInstance::set_material)
        .def_property_readonly("material_count", &GeometryInstance::material_count)
        .def("material", &GeometryInstance::material)
        .def_property("visibility_mask", &GeometryInstance::visibility_mask,
                      &GeometryInstance::set_visibility_mask,
                      "8-bit mask (default 0xff): rays whose mask shares no bit with it skip "
                      "the instance's primitives")
        .def_property("instance_id", &GeometryInstance::instance_id,
                      &GeometryInstance::set_instance_id,
                      "User id that hit programs read with geometry_instance_id() (default 0)")
        .def("__repr__", [](const GeometryInstance& x) { return repr(x); });
    add_variable_access(instance);

    py::class_<GeometryGroup, Node, std::shared_ptr<GeometryGroup>>(
        m, "GeometryGroup", "Geometry instances under one acceleration structure.")
        .def("add_child", &GeometryGroup::add_child, py::arg("instance"),
             "Appends a GeometryInstance; returns its index.")
        .def("set_child", &GeometryGroup::set_child)
        .def("remove_child", &GeometryGroup::remove_child)
        .def_property_readonly("child_count", &GeometryGroup::child_count)
        .def("child", &GeometryGroup::child)
        .def_property_readonly("children", &GeometryGroup::children)
        .def_property("acceleration", &GeometryGroup::acceleration,
                      &GeometryGroup::set_acceleration);
}

}  // namespace lucent::python

#include "array_args.h"

#include <cstring>
#include <sstream>

namespace lucent::python {

namespace {

std::string dtype_name(const py::array& a) {
    return py::str(a.dtype()).cast<std::string>();
}

/// The value as a numpy array: arrays as they are, Python sequences through numpy.asarray
/// (whose dtype is then checked like any array's); anything else a TypeError.
py::array as_array(const py::handle& value, const std::string& what) {
    if (py::isinstance<py::array>(value)) return py::reinterpret_borrow<py::array>(value);
    if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value))
        return py::module_::import("numpy").attr("asarray")(value);
    throw py::type_error(what + "; got " + py::str(py::type::of(value)).cast<std::string>());
}

bool shape_matches(const py::array& a, std::initializer_list<py::ssize_t> shape) {
    if (a.ndim() != py::ssize_t(shape.size())) return false;
    py::ssize_t axis = 0;
    for (py::ssize_t expected : shape) {
        if (expected >= 0 && a.shape(axis) != expected) return false;
        ++axis;
    }
    return true;
}

}  // namespace

std::string describe_array(const py::array& a) {
    std::ostringstream out;
    out << "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) out << (i ? ", " : "") << a.shape(i);
    out << (a.ndim() == 1 ? ",)" : ")") << " " << dtype_name(a);
    return out.str();
}

std::string shape_text(std::initializer_list<py::ssize_t> shape, const char* free_name) {
    std::ostringstream out;
    out << "(";
    bool first = true;
    for (py::ssize_t s : shape) {
        out << (first ? "" : ", ");
        if (s < 0)
            out << free_name;
        else
            out << s;
        first = false;
    }
    out << (shape.size() == 1 ? ",)" : ")");
    return out.str();
}

py::array_t<float> float32_array(const py::handle& value, const char* where, const char* name,
                                 std::initializer_list<py::ssize_t> shape, const char* free_name,
                                 py::ssize_t& free_size) {
    const std::string expected = std::string(where) + ": " + name + " must be a C-contiguous " +
                                 shape_text(shape, free_name) +
                                 " float32 array (float64 is converted)";
    py::array a = as_array(value, expected);
    const char kind = a.dtype().kind();
    const bool f32 = a.dtype().is(py::dtype::of<float>());
    const bool f64 = a.dtype().is(py::dtype::of<double>());
    if (!f32 && !f64)
        throw py::type_error(expected + "; got " + describe_array(a) +
                             (kind == 'f' || kind == 'i' || kind == 'u'
                                  ? " (convert it with .astype(np.float32))"
                                  : ""));
    if (!shape_matches(a, shape)) throw py::value_error(expected + "; got " + describe_array(a));
    if (!(a.flags() & py::array::c_style))
        throw py::value_error(expected + "; got a non-contiguous " + describe_array(a) +
                              " view (pass np.ascontiguousarray(" + name + "))");
    py::ssize_t axis = 0;
    for (py::ssize_t s : shape) {
        if (s < 0) free_size = a.shape(axis);
        ++axis;
    }
    if (f32) return py::reinterpret_borrow<py::array_t<float>>(a);
    return py::array_t<float>(a);  // float64: a converted copy
}

py::array_t<uint32_t> index_array(const py::handle& value, const char* where, const char* name,
                                  size_t vertex_count) {
    const std::string expected = std::string(where) + ": " + name +
                                 " must be a C-contiguous (M, 3) uint32 array (other integer "
                                 "dtypes are converted)";
    py::array a = as_array(value, expected);
    const char kind = a.dtype().kind();
    if (kind != 'i' && kind != 'u')
        throw py::type_error(expected + "; got " + describe_array(a));
    if (!shape_matches(a, {-1, 3})) throw py::value_error(expected + "; got " + describe_array(a));
    if (!(a.flags() & py::array::c_style))
        throw py::value_error(expected + "; got a non-contiguous " + describe_array(a) +
                              " view (pass np.ascontiguousarray(" + name + "))");
    if (a.shape(0) == 0) throw py::value_error(std::string(where) + ": " + name + " is empty; a mesh needs at least one triangle");
    // Every index is checked in the input's own type, before any conversion can wrap it.
    py::module_ np = py::module_::import("numpy");
    const long long lo = np.attr("min")(a).cast<long long>();
    const unsigned long long hi =
        kind == 'u' ? np.attr("max")(a).cast<unsigned long long>()
                    : (unsigned long long)std::max(0LL, np.attr("max")(a).cast<long long>());
    if (lo < 0 || hi >= vertex_count) {
        py::array bad = np.attr("argwhere")(
            np.attr("logical_or")(np.attr("less")(a, 0), np.attr("greater_equal")(a, vertex_count)));
        const py::ssize_t tri = bad.attr("__getitem__")(py::make_tuple(0, 0)).cast<py::ssize_t>();
        const py::ssize_t corner = bad.attr("__getitem__")(py::make_tuple(0, 1)).cast<py::ssize_t>();
        throw py::value_error(std::string(where) + ": " + name + "[" + std::to_string(tri) + ", " +
                              std::to_string(corner) + "] = " +
                              py::str(a.attr("__getitem__")(py::make_tuple(tri, corner)))
                                  .cast<std::string>() +
                              " is out of range; indices must be in [0, " +
                              std::to_string(vertex_count) + ") for " +
                              std::to_string(vertex_count) + " vertices");
    }
    if (a.dtype().is(py::dtype::of<uint32_t>()))
        return py::reinterpret_borrow<py::array_t<uint32_t>>(a);
    return py::array_t<uint32_t>(a);
}

py::array_t<float> interval_array(const py::handle& value, const char* where, const char* name,
                                  py::ssize_t rays) {
    // A number: a Python float or int, a numpy scalar, or a 0-d array.
    const py::object number = py::module_::import("numpy").attr("number");
    const bool zero_d =
        py::isinstance<py::array>(value) && py::reinterpret_borrow<py::array>(value).ndim() == 0;
    if (py::isinstance<py::bool_>(value) || (py::isinstance<py::array>(value) && zero_d &&
                                              py::reinterpret_borrow<py::array>(value).dtype().kind() == 'b'))
        throw py::type_error(std::string(where) + ": " + name +
                             " must be a number or an (R,) float32 array; got a bool");
    if (py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value) ||
        py::isinstance(value, number) || zero_d) {
        py::array_t<float> one(1);
        try {
            one.mutable_at(0) = py::float_(value.attr("__float__")()).cast<float>();
        } catch (const py::error_already_set&) {
            throw py::type_error(std::string(where) + ": " + name +
                                 " must be a number or an (R,) float32 array; got " +
                                 py::str(py::type::of(value)).cast<std::string>());
        }
        return one;
    }
    py::ssize_t n = 0;
    py::array_t<float> a = float32_array(value, where, name, {-1}, "R", n);
    if (n != rays)
        throw py::value_error(std::string(where) + ": " + name + " has " + std::to_string(n) +
                              " values for " + std::to_string(rays) +
                              " rays; give one number for every ray or one per ray");
    return a;
}

}  // namespace lucent::python

// Variables from Python: `scope["name"] = value` on a Context, Program, Material,
// GeometryInstance or Geometry, with the value's kind chosen from the Python value (a
// record field then checks it, as in C++: int and unsigned convert when they fit). A
// Python float is a float, an int an int (or unsigned beyond 2^31), a tuple or list of 2-4
// numbers a float vector, a numpy array its dtype's vector (float32, int32, uint32).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstring>
#include <limits>

#include "array_args.h"
#include "bindings.h"

namespace lucent::python {

namespace {

[[noreturn]] void bad_value(const VariableScope& scope, const std::string& name,
                            const py::handle& value, const std::string& why) {
    throw py::type_error(scope.scope_name() + "['" + name + "']: " + why + "; got " +
                         py::repr(value).cast<std::string>() +
                         ". A variable is a number, a tuple or numpy array of 2 to 4 numbers "
                         "(float32, int32 or uint32), a (3, 4) matrix, a Buffer, a node "
                         "(Group, GeometryGroup, Transform, Selector), a TextureSampler or a "
                         "callable Program");
}

template <class T>
VariableValue vector_value(const py::array& a) {
    T v{};
    std::memcpy(&v, a.data(), sizeof(T));
    return make_plain_value(v);
}

/// An integer as int when it fits, else unsigned when it fits.
VariableValue integer_value(const VariableScope& scope, const std::string& name,
                            const py::handle& value) {
    const py::int_ i = py::int_(value.attr("__int__")());
    const long long v = PyLong_AsLongLong(i.ptr());
    if (v == -1 && PyErr_Occurred()) {
        PyErr_Clear();
        bad_value(scope, name, value, "an integer beyond 32 bits");
    }
    if (v >= std::numeric_limits<int>::min() && v <= std::numeric_limits<int>::max())
        return make_plain_value(int(v));
    if (v >= 0 && v <= std::numeric_limits<unsigned>::max()) return make_plain_value(unsigned(v));
    bad_value(scope, name, value, "an integer beyond 32 bits");
}

VariableValue array_value(const VariableScope& scope, const std::string& name,
                          const py::handle& value) {
    py::module_ np = py::module_::import("numpy");
    py::array a;
    if (py::isinstance<py::tuple>(value) || py::isinstance<py::list>(value)) {
        // A tuple or list is a float vector: (0, 0, 1) is a position or colour far more
        // often than an int3, which a numpy int32 or uint32 array gives.
        try {
            a = np.attr("asarray")(value, "float32");
        } catch (const py::error_already_set&) {
            bad_value(scope, name, value, "a sequence that is not of numbers");
        }
    } else {
        a = np.attr("asarray")(value);
    }
    const char kind = a.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u' && kind != 'b')
        bad_value(scope, name, value, "a sequence of " + describe_array(a));
    if (a.ndim() == 0) {
        if (kind == 'f') return make_plain_value(a.attr("item")().cast<float>());
        if (kind == 'u' && a.dtype().itemsize() >= 4)
            return make_plain_value(a.attr("item")().cast<unsigned>());
        return integer_value(scope, name, a.attr("item")());
    }
    if (a.ndim() == 2 && a.shape(0) == 3 && a.shape(1) == 4) {
        py::array m = np.attr("ascontiguousarray")(a, "float32");
        return vector_value<Matrix4x3>(m);
    }
    if (a.ndim() != 1 || a.shape(0) < 2 || a.shape(0) > 4)
        bad_value(scope, name, value, "a " + describe_array(a) + " array");
    const py::ssize_t n = a.shape(0);
    if (kind == 'f') {
        py::array f = np.attr("ascontiguousarray")(a, "float32");
        return n == 2 ? vector_value<float2>(f) : n == 3 ? vector_value<float3>(f)
                                                         : vector_value<float4>(f);
    }
    // Integers: uint32 arrays stay unsigned, every other integer array becomes int32 when
    // its values fit.
    const bool as_unsigned = kind == 'u' && a.dtype().itemsize() == 4;
    const std::string target = as_unsigned ? "uint32" : "int32";
    py::array converted = np.attr("ascontiguousarray")(a, target);
    if (!np.attr("array_equal")(converted, a).cast<bool>())
        bad_value(scope, name, value, "integers that do not fit " + target);
    if (as_unsigned)
        return n == 2 ? vector_value<uint2>(converted) : n == 3 ? vector_value<uint3>(converted)
                                                               : vector_value<uint4>(converted);
    return n == 2 ? vector_value<int2>(converted) : n == 3 ? vector_value<int3>(converted)
                                                          : vector_value<int4>(converted);
}

template <class T>
py::tuple tuple_of(const VariableValue& v, int n) {
    T values[16];
    std::memcpy(values, v.bytes.data(), std::min(v.bytes.size(), sizeof values));
    py::tuple t(n);
    for (int i = 0; i < n; ++i) t[i] = py::cast(values[i]);
    return t;
}

}  // namespace

void set_variable(VariableScope& scope, const std::string& name, const py::handle& value) {
    VariableRef ref = scope[name];
    if (py::isinstance<Buffer>(value)) {
        ref = value.cast<std::shared_ptr<Buffer>>();
    } else if (py::isinstance<TextureSampler>(value)) {
        ref = value.cast<std::shared_ptr<TextureSampler>>();
    } else if (py::isinstance<Node>(value)) {
        ref = value.cast<std::shared_ptr<Node>>();
    } else if (py::isinstance<Program>(value)) {
        ref = value.cast<std::shared_ptr<Program>>();
    } else if (py::isinstance<py::float_>(value)) {
        ref = value.cast<float>();
    } else if (py::isinstance<py::int_>(value)) {  // bool too: 0 or 1
        ref.set(integer_value(scope, name, value));
    } else if (py::isinstance<py::array>(value) || py::isinstance<py::tuple>(value) ||
               py::isinstance<py::list>(value) ||
               py::isinstance(value, py::module_::import("numpy").attr("generic"))) {
        ref.set(array_value(scope, name, value));
    } else {
        bad_value(scope, name, value, "a value of an unknown kind");
    }
}

py::object get_variable(const VariableScope& scope, const std::string& name) {
    const VariableValue* v = scope.find_variable(name);
    if (!v) throw py::key_error(scope.scope_name() + " has no variable '" + name + "'");
    switch (v->kind) {
        case FieldKind::kFloat: return tuple_of<float>(*v, 1)[0];
        case FieldKind::kFloat2: return tuple_of<float>(*v, 2);
        case FieldKind::kFloat3: return tuple_of<float>(*v, 3);
        case FieldKind::kFloat4: return tuple_of<float>(*v, 4);
        case FieldKind::kInt: return tuple_of<int>(*v, 1)[0];
        case FieldKind::kInt2: return tuple_of<int>(*v, 2);
        case FieldKind::kInt3: return tuple_of<int>(*v, 3);
        case FieldKind::kInt4: return tuple_of<int>(*v, 4);
        case FieldKind::kUint: return tuple_of<unsigned>(*v, 1)[0];
        case FieldKind::kUint2: return tuple_of<unsigned>(*v, 2);
        case FieldKind::kUint3: return tuple_of<unsigned>(*v, 3);
        case FieldKind::kUint4: return tuple_of<unsigned>(*v, 4);
        case FieldKind::kMatrix4x3: {
            py::array_t<float> m({3, 4});
            std::memcpy(m.mutable_data(), v->bytes.data(), 12 * sizeof(float));
            return m;  // moved: C++20 treats a returned local as an rvalue
        }
        case FieldKind::kBuffer: return py::cast(v->buffer);
        case FieldKind::kTexture: return py::cast(v->texture);
        case FieldKind::kHandle: return py::cast(v->node);
        case FieldKind::kCallable: return py::cast(v->program);
        case FieldKind::kUserData:
            return py::bytes(reinterpret_cast<const char*>(v->bytes.data()), v->bytes.size());
    }
    return py::none();
}

}  // namespace lucent::python

// The parts of the `lucent` Python module, each bound in its own file, and what they share.
#pragma once

#include <pybind11/pybind11.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "lucent/lucent.h"

namespace lucent::python {

namespace py = pybind11;

void bind_errors(py::module_& m);          // module.cpp: lucent.Error, lucent.RankError
void bind_ranks(py::module_& m);           // ranks_binding.cpp
void bind_context(py::module_& m);         // context_binding.cpp
void bind_buffers(py::module_& m);         // buffer_binding.cpp
void bind_nodes(py::module_& m);           // nodes_binding.cpp
void bind_programs(py::module_& m);        // programs_binding.cpp
void bind_triangle_mesh(py::module_& m);   // mesh_binding.cpp
void bind_samples(py::module_& m);         // samples_binding.cpp
void bind_images(py::module_& m);          // images_binding.cpp
void bind_bench(py::module_& m);           // bench_binding.cpp: bench_rays
void bind_bench_suite(py::module_& m);     // bench_suite_binding.cpp: the other benchmarks
void bind_tea(py::module_& m);             // tea_binding.cpp: tea, tea_statistics, noise

/// A path argument (str or os.PathLike, as text): a TypeError "<call>: <name> must be <what>
/// (str or os.PathLike); got ..." otherwise (bench_binding.cpp).
std::string path_argument(const py::object& value, const char* call, const char* name,
                          const char* what);
/// Runs `measure` (a bench_*_json call) without the GIL and returns its JSON document as
/// a dict (bench_binding.cpp).
py::object document_of(const std::function<std::string()>& measure);

/// The class lucent.RankError (module.cpp), for code that tells it from other errors.
PyObject* rank_error_type();

/// A `ranks=` argument: None (null: this process alone) or a lucent.Ranks; a TypeError
/// naming `what` otherwise (ranks_binding.cpp).
std::shared_ptr<Ranks> ranks_argument(const py::object& ranks, const char* what);

/// A point or vector keyword (a camera's eye, look, up, light): three numbers; a ValueError
/// "<what> must be three numbers (x, y, z); got ..." otherwise (samples_binding.cpp).
float3 three_numbers(const py::handle& value, const std::string& what);

/// A `devices=` argument: None (empty: the backend's one device), a string ('0,1', 'cpu,0',
/// 'all') or a sequence of items ('cpu', 0); lucent.Error naming a bad item
/// (context_binding.cpp).
std::vector<DeviceSpec> device_list(const py::object& devices);

/// "auto", "cpu" or "cuda"; a ValueError naming `what` otherwise.
BackendKind backend_kind(const std::string& name, const char* what);

/// "input", "output" or "input_output"; a ValueError otherwise (buffer_binding.cpp).
BufferType buffer_type_from(const std::string& name);
/// A buffer size from Python: width, (width,), (width, height) or (width, height, depth).
std::vector<unsigned> parse_buffer_size(const py::handle& shape);

/// "sah", "none" or "gpu_hploc"; a ValueError otherwise (nodes_binding.cpp).
Builder builder_from_name(const std::string& name);

/// The TypeInfo of a built-in element or variable type by its Python name ("float3",
/// "uint", "uint8", "matrix4x3"), or of a struct a compiled module's records or payloads
/// use, by its C++ name ("lucent_tests::CastRay"); a ValueError listing the names otherwise.
const TypeInfo& type_by_name(const std::string& name, const char* what);
/// The Python name of a type for messages and Buffer.element.
std::string type_name(const TypeInfo& type);

/// Adds obj["name"] = value, obj["name"], del obj["name"] and obj.variables() to a class
/// whose C++ type is a VariableScope (variables_binding.cpp).
template <class Class>
void add_variable_access(Class& cls);
void set_variable(VariableScope& scope, const std::string& name, const py::handle& value);
py::object get_variable(const VariableScope& scope, const std::string& name);

template <class Class>
void add_variable_access(Class& cls) {
    using T = typename Class::type;
    cls.def(
           "__setitem__",
           [](T& self, const std::string& name, const py::handle& value) {
               set_variable(self, name, value);
           },
           "Sets a variable: a number, a tuple or numpy array of 2-4 numbers (float32 or "
           "int32/uint32 vectors), a (3, 4) matrix, a Buffer, a node, a TextureSampler or a "
           "callable Program.")
        .def("__getitem__", [](const T& self, const std::string& name) {
            return get_variable(self, name);
        })
        .def("__delitem__", [](T& self, const std::string& name) {
            if (!self.find_variable(name))
                throw py::key_error(self.scope_name() + " has no variable '" + name + "'");
            self.remove_variable(name);
        })
        .def("__contains__", [](const T& self, const std::string& name) {
            return self.find_variable(name) != nullptr;
        })
        .def("variables", [](const T& self) {
            py::list names;
            for (const auto& [name, value] : self.variables()) names.append(name);
            return names;
        }, "The names of the variables set here.");
}

}  // namespace lucent::python

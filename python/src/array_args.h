// Checking numpy arguments: each check names the function, the argument, the shape and
// dtype it expects and what it was given, so a wrong array is a Python exception (TypeError
// for a dtype, ValueError for a shape or layout), never a crash or a silent reinterpretation.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <string>

namespace lucent::python {

namespace py = pybind11;

/// "(5, 3) float64" for messages.
std::string describe_array(const py::array& a);
/// "(R, 3)" from the expected shape, -1 standing for a free size named by `free_name`.
std::string shape_text(std::initializer_list<py::ssize_t> shape, const char* free_name);

/// A C-contiguous float32 array of `shape` (-1: any size, given back in `free_size`).
/// float64 input is converted to float32 (a copy); any other dtype is a TypeError, a
/// non-contiguous array, a wrong shape or a non-array a ValueError.
py::array_t<float> float32_array(const py::handle& value, const char* where, const char* name,
                                 std::initializer_list<py::ssize_t> shape, const char* free_name,
                                 py::ssize_t& free_size);

/// The (M, 3) triangle indices as uint32: uint32 as given, any other integer dtype
/// converted after checking every index is in [0, vertex_count).
py::array_t<uint32_t> index_array(const py::handle& value, const char* where, const char* name,
                                  size_t vertex_count);

/// A ray interval bound: a Python number (one value for every ray) or an (R,) float32 /
/// float64 array.
py::array_t<float> interval_array(const py::handle& value, const char* where, const char* name,
                                  py::ssize_t rays);

}  // namespace lucent::python

// Buffers as numpy arrays. A Buffer's host copy is viewed without copying: buffer.numpy()
// is a read-only view, `with buffer.map() as a:` a writable one whose changes the next
// launch sees (the exit unmaps), buffer.upload(array) copies in and buffer.download()
// copies out. A view keeps its buffer alive; while any view exists the buffer cannot be
// resized (BufferError), as a bytearray with exported views cannot.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <unordered_map>
#include <vector>

#include "array_args.h"
#include "bindings.h"

namespace lucent::python {

namespace {

/// How an element type looks in numpy: a scalar dtype and the element's own axes.
struct ElementLayout {
    py::dtype dtype;
    std::vector<py::ssize_t> axes;  // () for scalars, (3,) for float3, (3, 4) for matrix4x3
};

ElementLayout element_layout(const TypeInfo& element) {
    const std::string name = type_name(element);
    auto vec = [](const std::string& n) -> std::vector<py::ssize_t> {
        const char last = n.back();
        if (last >= '2' && last <= '4') return {py::ssize_t(last - '0')};
        return {};
    };
    if (name.rfind("float", 0) == 0) return {py::dtype::of<float>(), vec(name)};
    if (name.rfind("int", 0) == 0) return {py::dtype::of<int32_t>(), vec(name)};
    if (name == "uint8") return {py::dtype::of<uint8_t>(), {}};
    if (name.rfind("uint", 0) == 0) return {py::dtype::of<uint32_t>(), vec(name)};
    if (name == "matrix4x3") return {py::dtype::of<float>(), {3, 4}};
    // A struct of a compiled module: its bytes.
    return {py::dtype::of<uint8_t>(), {py::ssize_t(element.size)}};
}

/// The numpy shape of a buffer: (depth, height, width) as far as it has dimensions, then
/// the element's axes.
std::vector<py::ssize_t> buffer_shape(const Buffer& b) {
    std::vector<py::ssize_t> shape;
    const uint3 s = b.size();
    if (b.dimensionality() >= 3) shape.push_back(s.z);
    if (b.dimensionality() >= 2) shape.push_back(s.y);
    shape.push_back(s.x);
    for (py::ssize_t a : element_layout(b.element()).axes) shape.push_back(a);
    return shape;
}

/// Live views per buffer (the GIL guards it).
std::unordered_map<const Buffer*, int>& live_views() {
    static std::unordered_map<const Buffer*, int> views;
    return views;
}

/// Brings the host copy up to date: a GPU download, or, for an index-local buffer of a
/// Context spanning ranks, a gather every rank makes (docs/distributed.md), so the GIL is
/// released while it may wait.
void sync_host_copy(const Buffer& buffer) {
    py::gil_scoped_release release;
    buffer.sync_from_device();
}

py::array view_of(const std::shared_ptr<Buffer>& buffer, bool writable) {
    sync_host_copy(*buffer);
    ++live_views()[buffer.get()];
    auto* keep = new std::shared_ptr<Buffer>(buffer);
    py::capsule owner(keep, [](void* p) {
        auto* held = static_cast<std::shared_ptr<Buffer>*>(p);
        if (--live_views()[held->get()] == 0) live_views().erase(held->get());
        delete held;
    });
    const ElementLayout layout = element_layout(buffer->element());
    py::array a(layout.dtype, buffer_shape(*buffer), {}, buffer->raw(), owner);
    if (!writable) a.attr("flags").attr("writeable") = false;
    return a;
}

BufferType buffer_type(const std::string& name) {
    if (name == "input") return BufferType::kInput;
    if (name == "output") return BufferType::kOutput;
    if (name == "input_output") return BufferType::kInputOutput;
    throw py::value_error("buffer type: expected 'input', 'output' or 'input_output'; got '" +
                          name + "'");
}

/// A writable view for `with buffer.map() as a:`; the exit unmaps.
struct MappedBuffer {
    std::shared_ptr<Buffer> buffer;
    py::object view;
};

void check_no_views(const Buffer& b, const char* what) {
    auto it = live_views().find(&b);
    if (it != live_views().end() && it->second > 0)
        throw py::buffer_error(b.describe() + ": cannot " + what + " while " +
                               std::to_string(it->second) +
                               " numpy view(s) of it exist; delete them (del a) or copy them "
                               "(a.copy()) first");
}

}  // namespace

std::vector<unsigned> parse_buffer_size(const py::handle& shape) {
    std::vector<unsigned> dims;
    if (py::isinstance<py::int_>(shape)) {
        dims.push_back(shape.cast<unsigned>());
    } else {
        for (const py::handle& d : shape) dims.push_back(d.cast<unsigned>());
    }
    if (dims.empty() || dims.size() > 3)
        throw py::value_error("buffer size: expected width, (width,), (width, height) or "
                              "(width, height, depth)");
    return dims;
}

void bind_buffers(py::module_& m) {
    py::class_<MappedBuffer>(m, "MappedBuffer")
        .def("__enter__", [](MappedBuffer& mb) { return mb.view; })
        .def("__exit__", [](MappedBuffer& mb, const py::args&) {
            mb.view = py::none();
            mb.buffer->unmap();  // new contents: uploaded at the next launch
        });

    py::class_<Buffer, std::shared_ptr<Buffer>>(m, "Buffer",
                                                "A typed 1D, 2D or 3D array shared by the host "
                                                "and programs.")
        .def_property_readonly("name", [](const Buffer& b) { return b.name(); })
        .def_property_readonly("type",
                               [](const Buffer& b) { return std::string(buffer_type_name(b.type())); })
        .def_property_readonly("element", [](const Buffer& b) { return type_name(b.element()); })
        .def_property_readonly("dimensionality", &Buffer::dimensionality)
        .def_property_readonly("size",
                               [](const Buffer& b) {
                                   const uint3 s = b.size();
                                   return py::make_tuple(s.x, s.y, s.z);
                               },
                               "(width, height, depth); unused dimensions are 1")
        .def_property_readonly("shape",
                               [](const Buffer& b) { return py::tuple(py::cast(buffer_shape(b))); },
                               "The shape of its numpy views: (depth, height, width) as far "
                               "as it has dimensions, then the element's axes")
        .def("__len__", [](const Buffer& b) { return b.count(); })
        .def_property("launch_index_local", &Buffer::launch_index_local,
                      &Buffer::set_launch_index_local,
                      "True: launches touch element i only at launch index i (an "
                      "accumulation). A Context spanning ranks then keeps each rank's elements "
                      "where they were computed until something else reads the buffer; a "
                      "host read (numpy, map, download) is then collective: every rank makes "
                      "it (docs/distributed.md). No effect in one process.")
        .def(
            "resize",
            [](Buffer& b, unsigned width, unsigned height, unsigned depth) {
                check_no_views(b, "resize it");
                b.resize(width, height, depth);
            },
            py::arg("width"), py::arg("height") = 1u, py::arg("depth") = 1u,
            "New size (same dimensionality); the contents are zeroed.")
        .def(
            "numpy", [](const std::shared_ptr<Buffer>& b) { return view_of(b, false); },
            "A read-only numpy view of the host copy, without copying. After a GPU launch "
            "writes the buffer, take a new view to see its results.")
        .def(
            "map",
            [](const std::shared_ptr<Buffer>& b) {
                return MappedBuffer{b, view_of(b, true)};
            },
            "`with buffer.map() as a: a[...] = ...`: a writable view; the next launch sees "
            "what was written.")
        .def(
            "upload",
            [](Buffer& b, const py::array& values) {
                const ElementLayout layout = element_layout(b.element());
                const std::vector<py::ssize_t> shape = buffer_shape(b);
                py::array a = values;
                if (!a.dtype().is(layout.dtype)) a = values.attr("astype")(layout.dtype);
                bool same = a.ndim() == py::ssize_t(shape.size());
                for (size_t i = 0; same && i < shape.size(); ++i) same = a.shape(i) == shape[i];
                if (!same) {
                    std::string want = "(";
                    for (size_t i = 0; i < shape.size(); ++i)
                        want += (i ? ", " : "") + std::to_string(shape[i]);
                    want += shape.size() == 1 ? ",)" : ")";
                    throw py::value_error(b.describe() + ": upload of a " + describe_array(values) +
                                          " array; the buffer's shape is " + want + " " +
                                          py::str(py::handle(layout.dtype)).cast<std::string>() +
                                          " (resize the buffer first)");
                }
                a = py::module_::import("numpy").attr("ascontiguousarray")(a);
                sync_host_copy(b);
                std::memcpy(b.raw(), a.data(), size_t(a.nbytes()));
                b.unmap();
            },
            py::arg("values"), "Copies an array of the buffer's shape in (dtype converted).")
        .def(
            "download",
            [](const std::shared_ptr<Buffer>& b) { return view_of(b, false).attr("copy")(); },
            "A copy of the contents as a numpy array.")
        .def(
            "__array__",
            [](const std::shared_ptr<Buffer>& b, const py::object& dtype) {
                py::array a = view_of(b, false);
                return dtype.is_none() ? a : py::array(a.attr("astype")(dtype));
            },
            py::arg("dtype") = py::none())
        .def("__repr__", [](const Buffer& b) { return "<lucent." + b.describe() + ">"; });
}

BufferType buffer_type_from(const std::string& name) {
    return buffer_type(name);
}

}  // namespace lucent::python

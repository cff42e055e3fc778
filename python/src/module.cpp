// The `lucent` extension module (imported as lucent._lucent; python/lucent/__init__.py
// re-exports it): the engine's host API, ray queries on numpy arrays, and the samples.
#include <pybind11/pybind11.h>

#include "bindings.h"
#include "lucent/version.h"

namespace lucent::python {

BackendKind backend_kind(const std::string& name, const char* what) {
    if (name == "auto") return BackendKind::kAuto;
    if (name == "cpu") return BackendKind::kCpu;
    if (name == "cuda") return BackendKind::kCuda;
    throw py::value_error(std::string(what) + ": expected 'auto', 'cpu' or 'cuda'; got '" + name +
                          "'");
}

namespace {
py::exception<Error>* g_error = nullptr;
py::exception<RankError>* g_rank_error = nullptr;
}  // namespace

PyObject* rank_error_type() {
    return g_rank_error->ptr();
}

void bind_errors(py::module_& m) {
    // lucent::Error (a wrong call, a failed compile or launch) as lucent.Error, a
    // RuntimeError; its message names the object and the fix.
    // Never freed: a static object's destructor would run after the interpreter is gone.
    g_error = new py::exception<Error>(m, "Error", PyExc_RuntimeError);
    // lucent::RankError (a rank failed, or ranks diverged: docs/distributed.md) as
    // lucent.RankError, a lucent.Error that every rank raises alike, with failed_rank.
    g_rank_error = new py::exception<RankError>(m, "RankError", g_error->ptr());
    g_rank_error->attr("__doc__") =
        "A rank failed, as every rank of the group learns it at the same point: the message "
        "names the rank and the cause ('rank 2: ...'); failed_rank is that rank (the lowest "
        "that failed), or -1 when the ranks diverged (their launches differ).";
    g_rank_error->attr("failed_rank") = py::none();
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const RankError& e) {
            py::object error = py::reinterpret_borrow<py::object>(g_rank_error->ptr())(e.what());
            error.attr("failed_rank") = e.failed_rank();
            PyErr_SetObject(g_rank_error->ptr(), error.ptr());
        } catch (const Error& e) {
            PyErr_SetString(g_error->ptr(), e.what());
        }
    });
}

}  // namespace lucent::python

PYBIND11_MODULE(_lucent, m) {
    using namespace lucent::python;
    m.doc() = "Lucent, a programmable ray tracing engine: ray queries on numpy arrays "
              "(TriangleMesh), the engine's host API (Context and what it creates), and the "
              "samples (render).";
    m.attr("__version__") = lucent::version();
#ifdef LUCENT_HAVE_CUDA
    m.attr("cuda_built") = true;  // the CUDA backend (and jit_check_sm) is in this build
#else
    m.attr("cuda_built") = false;
#endif
    bind_errors(m);
    bind_programs(m);
    bind_buffers(m);
    bind_nodes(m);
    bind_ranks(m);
    bind_context(m);
    bind_triangle_mesh(m);
    bind_samples(m);
    bind_images(m);
    bind_bench(m);
    bind_bench_suite(m);
    bind_tea(m);
}

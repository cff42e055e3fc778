// lucent.Ranks from Python (lucent/ranks.h, docs/distributed.md): the processes of
// `mpirun -np N python3 script.py` as one group a Context spans. Ranks.world() initialises
// MPI itself (no mpi4py), so every rank runs the same script and every launch is spread.
#include <pybind11/pybind11.h>

#include <exception>

#include "bindings.h"

namespace lucent::python {

namespace {

/// The text a rank passes to the agreement: a str, or an exception (its message, or its
/// type's name when it has none).
std::string failure_text(const py::object& failure) {
    std::string text;
    if (py::isinstance<py::str>(failure)) {
        text = failure.cast<std::string>();
    } else if (PyExceptionInstance_Check(failure.ptr())) {
        text = py::str(failure).cast<std::string>();
        if (text.empty()) text = py::type::of(failure).attr("__name__").cast<std::string>();
    } else {
        throw py::type_error(
            "Ranks.agree: failure must be None (this rank did not fail), a str "
            "saying what failed, or the exception caught; got " +
            py::repr(failure).cast<std::string>());
    }
    if (text.empty())
        throw py::value_error(
            "Ranks.agree: failure must say what failed; got an empty string "
            "(pass None when this rank did not fail)");
    return text;
}

/// Under a launcher, an exception no rank catches would end its script while the others wait
/// for it in their next agreement or launch, and its interpreter would then wait for them in
/// MPI's finalisation (a collective): the job would hang. So an uncaught exception prints its
/// traceback (a RankError, which every rank raises alike, on rank 0 only, as the CLI prints
/// it) and leaves the process at once with status 1; mpirun then ends the job.
void exit_on_uncaught_exception(int rank) {
    static bool installed = false;
    if (installed) return;
    installed = true;
    py::module_ sys = py::module_::import("sys");
    py::object previous = sys.attr("excepthook");
    py::object rank_error = py::reinterpret_borrow<py::object>(rank_error_type());
    py::object os_exit = py::module_::import("os").attr("_exit");
    sys.attr("excepthook") = py::cpp_function(
        [previous, rank_error, os_exit, rank](const py::object& type, const py::object& value,
                                              const py::object& traceback) {
            const bool every_rank_has_it =
                PyType_Check(type.ptr()) && PyObject_IsSubclass(type.ptr(), rank_error.ptr()) == 1;
            if (rank == 0 || !every_rank_has_it) previous(type, value, traceback);
            py::module_ sys = py::module_::import("sys");
            for (const char* stream : {"stdout", "stderr"})
                if (!sys.attr(stream).is_none()) sys.attr(stream).attr("flush")();
            os_exit(1);
        });
}

}  // namespace

std::shared_ptr<Ranks> ranks_argument(const py::object& ranks, const char* what) {
    if (ranks.is_none()) return nullptr;
    if (!py::isinstance<Ranks>(ranks))
        throw py::type_error(std::string(what) +
                             " must be a lucent.Ranks (lucent.Ranks.world()) or None; got " +
                             py::repr(ranks).cast<std::string>());
    return ranks.cast<std::shared_ptr<Ranks>>();
}

void bind_ranks(py::module_& m) {
    py::class_<Ranks, std::shared_ptr<Ranks>>(
        m, "Ranks",
        "The processes (MPI ranks) a Context spans: Context(ranks=lucent.Ranks.world()) "
        "spreads every launch over them, and every rank's outputs hold the whole image "
        "(docs/distributed.md). Every rank runs the same script: `mpirun -np 3 python3 "
        "script.py`.")
        .def_static(
            "world",
            [] {
                std::shared_ptr<Ranks> world;
                {
                    py::gil_scoped_release release;  // collective: waits for every rank
                    world = Ranks::world();
                }
                if (world->size() > 1) exit_on_uncaught_exception(world->rank());
                return world;
            },
            "The ranks of MPI_COMM_WORLD. MPI is initialised here if it is not yet (and "
            "finalised at exit); collective: every rank calls it. Without a launcher (no "
            "mpirun), and in a build without MPI: a group of this process alone. Raises "
            "lucent.Error under mpirun in a build without MPI. With more than one rank, an "
            "exception the script does not catch prints its traceback (a RankError on rank 0 "
            "only) and ends the process with status 1 at once, so mpirun ends the job instead "
            "of the other ranks waiting for this one.")
        .def_static("built_with_mpi", &Ranks::built_with_mpi,
                    "Whether this build of Lucent has MPI (LUCENT_MPI at configure time).")
        .def_static("launched_as_rank", &Ranks::launched_as_rank,
                    "Whether a launcher (mpirun, srun with PMIx) started this process as one "
                    "of several.")
        .def_property_readonly("rank", &Ranks::rank, "This process's rank, 0..size-1.")
        .def_property_readonly("size", &Ranks::size, "How many ranks the group has.")
        .def(
            "agree",
            [](Ranks& ranks, const py::object& failure) {
                if (failure.is_none()) {
                    py::gil_scoped_release release;
                    ranks.agree();
                    return;
                }
                const std::string text = failure_text(failure);
                py::gil_scoped_release release;
                ranks.agree(&text);
            },
            py::arg("failure") = py::none(),
            "An agreement point: every rank calls it at the same place. A rank that passes "
            "its failure (a str, or the exception it caught) makes every rank raise "
            "lucent.RankError 'rank R: <failure>' (R the lowest failing rank, its "
            "failed_rank); with none it returns. Call it where a rank may have failed "
            "outside a launch (a file missing on one node), so the others do not wait for it "
            "in the next launch.")
        .def("__repr__", [](const Ranks& r) {
            return "<lucent.Ranks: rank " + std::to_string(r.rank()) + " of " +
                   std::to_string(r.size()) + ">";
        });
}

}  // namespace lucent::python

// `lucent bench rays` from Python: lucent.bench_rays(scene, ...) traces BENCH.md's ray sets
// as the CLI does (bench/rays/rays_bench.h, bench_rays_json) and returns the document that
// `lucent bench rays --json` prints, as a dict.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <functional>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "bench/rays/rays_bench.h"
#include "bindings.h"

namespace lucent::python {

namespace {

/// A camera keyword (eye, look, up, light): three numbers.
float3 camera_point(const py::object& value, const char* name) {
    return three_numbers(value, std::string("bench_rays: ") + name);
}

py::object bench_rays(const py::object& scene,
                      const std::optional<std::pair<unsigned, unsigned>>& size, int repeat,
                      unsigned threads, bool peer, bool programs, const std::string& backend,
                      const std::string& builder, const py::object& eye, const py::object& look,
                      const py::object& up, const std::optional<float>& fov,
                      const py::object& light) {
    bench::RaysOptions options;
    options.scene = path_argument(scene, "bench_rays", "scene", "an OBJ file's path");
    // None: the CLI's default, BENCH.md's 3840x2160 on the GPU.
    std::tie(options.width, options.height) =
        size.value_or(backend == "cuda" ? std::pair{3840u, 2160u} : std::pair{1024u, 768u});
    options.repeat = repeat;
    options.threads = threads;
    options.peer = peer;
    options.programs = programs;
    options.backend = backend;
    if (builder != "auto" && builder != "gpu" && builder != "sah")
        throw py::value_error("bench_rays: builder is \"" + builder +
                              "\"; use \"auto\", \"gpu\" or \"sah\" (as `bench rays --builder`)");
    options.builder = builder == "sah" ? Builder::kBinnedSah : Builder::kAuto;
    options.tree_upgrades = builder == "gpu" ? TreeUpgrades::kOff : TreeUpgrades::kWithBuild;
    // A partial camera would mix given and default values: refuse it, as the CLI does.
    const std::pair<const char*, bool> camera[] = {{"eye", !eye.is_none()},
                                                   {"look", !look.is_none()},
                                                   {"up", !up.is_none()},
                                                   {"fov", fov.has_value()},
                                                   {"light", !light.is_none()}};
    std::string given, missing;
    for (const auto& [name, is_given] : camera)
        (is_given ? given : missing) += std::string(" ") + name;
    if (!given.empty() && !missing.empty())
        throw py::value_error("bench_rays: the camera keywords go together: given" + given +
                              ", missing" + missing +
                              " (or give none to use cameras.txt beside the scene)");
    if (!given.empty()) {
        options.has_camera = true;
        options.eye = camera_point(eye, "eye");
        options.look = camera_point(look, "look");
        options.up = camera_point(up, "up");
        options.fov = *fov;
        options.light = camera_point(light, "light");
    }
    return document_of([&] { return bench::bench_rays_json(options); });
}

}  // namespace

std::string path_argument(const py::object& value, const char* call, const char* name,
                          const char* what) {
    const py::module_ os = py::module_::import("os");
    const std::string named = std::string(call) + ": " + name;
    if (!py::isinstance<py::str>(value) && !py::isinstance(value, os.attr("PathLike")))
        throw py::type_error(named + " must be " + what + " (str or os.PathLike); got " +
                             py::repr(value).cast<std::string>());
    const py::object path = os.attr("fspath")(value);
    if (!py::isinstance<py::str>(path))
        throw py::type_error(named + " must be a text path, not bytes; got " +
                             py::repr(value).cast<std::string>());
    return path.cast<std::string>();
}

py::object document_of(const std::function<std::string()>& measure) {
    std::string document;
    {
        py::gil_scoped_release release;  // the benchmark runs no Python
        document = measure();
    }
    return py::module_::import("json").attr("loads")(document);
}

void bind_bench(py::module_& m) {
    m.def("bench_rays", &bench_rays, py::arg("scene"), py::kw_only(),
          py::arg("size") = py::none(), py::arg("repeat") = 5,
          py::arg("threads") = 0u, py::arg("peer") = true, py::arg("programs") = false,
          py::arg("backend") = "cpu", py::arg("builder") = "auto", py::arg("eye") = py::none(),
          py::arg("look") = py::none(), py::arg("up") = py::none(),
          py::arg("fov") = std::optional<float>{}, py::arg("light") = py::none(),
          "Traces the ray sets of BENCH.md (primary, shadow, diffuse) over an OBJ scene as "
          "`lucent bench rays --json` does, and returns its document as a dict: Mrays/s and "
          "checksums of Lucent's kernels, ray streams and, with peer=True, Embree on the same "
          "threads; with programs=True also the engine path (a program module launched by a "
          "Context). The camera is cameras.txt's beside the scene unless eye, look, up, fov "
          "and light are all given. size is (width, height), by default (1024, 768), or "
          "(3840, 2160) on 'cuda'. backend is 'cpu' or 'cuda'; builder 'auto', 'gpu' or "
          "'sah'. Keys: docs/cli.md, \"lucent bench rays\".");
}

}  // namespace lucent::python

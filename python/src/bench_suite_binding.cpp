// The benchmarks beside bench_rays from Python: lucent.bench_build, bench_spheres,
// bench_curves, bench_igi, bench_fog and bench_tea each measure as the `lucent bench ...`
// command of the same name does (bench/<name>/<name>_bench.h, bench_<name>_json) and return
// the document that its --json prints, as a dict. The keywords are the CLI's flags, with the
// same defaults; the benchmark checks their values and names a bad one.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "bench/build/build_bench.h"
#include "bench/curves/curves_bench.h"
#include "bench/fog/fog_bench.h"
#include "bench/igi/igi_bench.h"
#include "bench/spheres/spheres_bench.h"
#include "bench/tea/tea_bench.h"
#include "bindings.h"
#include "lucent/run_agreed.h"

namespace lucent::python {

namespace {

using ImageSize = std::optional<std::pair<unsigned, unsigned>>;

/// `size`, or the CLI's default for the backend when it is None (BENCH.md's 3840x2160 on the
/// GPU for the ray benchmarks).
std::pair<unsigned, unsigned> size_or(const ImageSize& size, std::pair<unsigned, unsigned> cpu,
                                      std::pair<unsigned, unsigned> cuda, BackendKind backend) {
    if (size) return *size;
    return backend == BackendKind::kCuda ? cuda : cpu;
}

py::object bench_build(const py::object& scene, int repeat, unsigned threads, bool peer,
                       const std::string& backend, unsigned subdivide, const ImageSize& size) {
    bench::BuildBenchOptions options;
    options.scene = path_argument(scene, "bench_build", "scene", "an OBJ file's path");
    options.repeat = repeat;
    options.threads = threads;
    options.peer = peer;
    // As the CLI's --backend: "auto" measures the CPU, so that the default figures compare.
    options.backend =
        backend_kind(backend, "bench_build: backend") == BackendKind::kCuda ? "cuda" : "cpu";
    options.subdivide = subdivide;
    std::tie(options.width, options.height) = size.value_or(std::pair{3840u, 2160u});
    return document_of([&] { return bench::bench_build_json(options); });
}

py::object bench_spheres(const std::string& backend, unsigned threads, unsigned count,
                         const ImageSize& size, int repeat) {
    bench::SpheresBenchOptions options;
    options.backend = backend_kind(backend, "bench_spheres: backend");
    options.threads = threads;
    options.count = count;
    std::tie(options.width, options.height) =
        size_or(size, {1024, 768}, {3840, 2160}, options.backend);
    options.repeat = repeat;
    return document_of([&] { return bench::bench_spheres_json(options); });
}

py::object bench_curves(const std::string& backend, unsigned threads, unsigned segments,
                        const std::string& curve_type, const ImageSize& size, int repeat) {
    static const std::map<std::string, CurveType> kTypes = {{"linear", kCurveLinear},
                                                            {"quadratic", kCurveQuadraticBSpline},
                                                            {"cubic", kCurveCubicBSpline},
                                                            {"catmull-rom", kCurveCatmullRom}};
    const auto type = kTypes.find(curve_type);
    if (type == kTypes.end())
        throw py::value_error("bench_curves: curve_type is '" + curve_type +
                              "'; use 'linear', 'quadratic', 'cubic' or 'catmull-rom' (as "
                              "`bench curves --type`)");
    bench::CurvesBenchOptions options;
    options.backend = backend_kind(backend, "bench_curves: backend");
    options.threads = threads;
    options.segments = segments;
    options.type = type->second;
    std::tie(options.width, options.height) =
        size_or(size, {640, 480}, {3840, 2160}, options.backend);
    options.repeat = repeat;
    return document_of([&] { return bench::bench_curves_json(options); });
}

py::object bench_igi(const py::object& scene, const std::string& backend, unsigned threads,
                     std::pair<unsigned, unsigned> size, unsigned frames,
                     std::vector<unsigned> vpls, unsigned downsample, unsigned interleave,
                     bool reflection_layer, const py::object& devices, const py::object& ranks) {
    bench::IgiBenchOptions options;
    options.scene =
        path_argument(scene, "bench_igi", "scene", "a built-in scene's name or a scene file");
    options.backend = backend_kind(backend, "bench_igi: backend");
    options.devices = device_list(devices);
    options.ranks = ranks_argument(ranks, "bench_igi: ranks");
    options.threads = threads;
    std::tie(options.width, options.height) = size;
    options.frames = frames;
    options.vpls = std::move(vpls);
    options.downsample = downsample;
    options.interleave = interleave;
    options.reflection_layer = reflection_layer;
    return document_of([&] {
        // Under ranks, a rank's failure is every rank's RankError, as in render().
        std::string document;
        run_agreed(options.ranks, [&] { document = bench::bench_igi_json(options); });
        return document;
    });
}

py::object bench_fog(const std::string& backend, unsigned threads,
                     std::pair<unsigned, unsigned> size, unsigned frames,
                     const py::object& devices) {
    bench::FogBenchOptions options;
    options.backend = backend_kind(backend, "bench_fog: backend");
    options.devices = device_list(devices);
    options.threads = threads;
    std::tie(options.width, options.height) = size;
    options.frames = frames;
    return document_of([&] { return bench::bench_fog_json(options); });
}

py::object bench_tea(const std::string& backend, unsigned threads, unsigned megabytes,
                     unsigned rounds, unsigned device, unsigned seed) {
    bench::TeaBenchOptions options;
    options.backend = backend_kind(backend, "bench_tea: backend");
    options.threads = threads;
    options.megabytes = megabytes;
    options.rounds = rounds;
    options.device = device;
    options.seed = seed;
    return document_of([&] { return bench::bench_tea_json(options); });
}

}  // namespace

void bind_bench_suite(py::module_& m) {
    const auto no_size = py::none();
    m.def("bench_build", &bench_build, py::arg("scene"), py::kw_only(), py::arg("repeat") = 5,
          py::arg("threads") = 0u, py::arg("peer") = true, py::arg("backend") = "cpu",
          py::arg("subdivide") = 0u, py::arg("size") = no_size,
          "Times the BVH build of an OBJ scene as `lucent bench build --json` does, and returns "
          "its document as a dict: the median build time, Mtris/s, SAH cost and node counts, "
          "and with peer=True Embree's high-quality build on the same threads. subdivide=N "
          "cuts each triangle into 4, N times (0-5). backend='cuda' times the GPU builder "
          "against the host's and traces BENCH.md's rays (size, default (3840, 2160)) through "
          "both trees. Keys: docs/cli.md, \"lucent bench build\".");
    m.def("bench_spheres", &bench_spheres, py::kw_only(), py::arg("backend") = "cpu",
          py::arg("threads") = 0u, py::arg("count") = 1000000u, py::arg("size") = no_size,
          py::arg("repeat") = 5,
          "Primary rays into a field of `count` spheres, the built-in spheres against the same "
          "spheres as a custom intersection program, as `lucent bench spheres --json`; returns "
          "its document as a dict. size defaults to (1024, 768), (3840, 2160) on 'cuda'. "
          "Raises lucent.Error when the two paths disagree.");
    m.def("bench_curves", &bench_curves, py::kw_only(), py::arg("backend") = "cpu",
          py::arg("threads") = 0u, py::arg("segments") = 100000u, py::arg("curve_type") = "cubic",
          py::arg("size") = no_size, py::arg("repeat") = 5,
          "Primary rays, and a diffuse ray per primary hit, into a head of hair of built-in "
          "curves (curve_type 'linear', 'quadratic', 'cubic' or 'catmull-rom'), as `lucent "
          "bench curves --json`; returns its document as a dict. size defaults to (640, 480), "
          "(3840, 2160) on 'cuda'.");
    m.def("bench_igi", &bench_igi, py::arg("scene") = "cornell", py::kw_only(),
          py::arg("backend") = "cpu", py::arg("threads") = 0u,
          py::arg("size") = std::pair<unsigned, unsigned>{800, 600}, py::arg("frames") = 10u,
          py::arg("vpls") = std::vector<unsigned>{30, 90, 180}, py::arg("downsample") = 4u,
          py::arg("interleave") = 3u, py::arg("reflection_layer") = true,
          py::arg("devices") = py::none(), py::arg("ranks") = py::none(),
          "Instant global illumination as Marques and Santos measure it (Fig. 4 and 5), as "
          "`lucent bench igi --json`: canonical IGI, then imperfect visibility, downsampling "
          "and interleaving added in turn, each at every VPL count; returns the document "
          "(frames/s and the stages' ms per configuration) as a dict. devices='0,1' spreads "
          "each frame's launches over devices, ranks=lucent.Ranks.world() over the ranks of "
          "mpirun (every rank calls it alike and gets the document).");
    m.def("bench_fog", &bench_fog, py::kw_only(), py::arg("backend") = "cpu",
          py::arg("threads") = 0u, py::arg("size") = std::pair<unsigned, unsigned>{1024, 768},
          py::arg("frames") = 30u, py::arg("devices") = py::none(),
          "Sebald's Table 1, as `lucent bench fog --json`: frames/s of the fog tutorial scene "
          "without fog and with fog marched at steps 0.1, 0.05 and 0.01, along one turn of the "
          "camera's orbit; returns the document as a dict. devices='0,1' spreads each "
          "frame's launches over devices.");
    m.def("bench_tea", &bench_tea, py::kw_only(), py::arg("backend") = "cpu",
          py::arg("threads") = 0u, py::arg("megabytes") = 2048u, py::arg("rounds") = 2u,
          py::arg("device") = 0u, py::arg("seed") = 0u,
          "Sebald's Table 2, as `lucent bench tea --json`: `megabytes` of TEA output in 1 MB "
          "launches with the fixed key against the generated per-device key, and a copy of the "
          "same size; returns the document (MB/s and XOR checksums) as a dict.");
}

}  // namespace lucent::python

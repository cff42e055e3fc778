// The samples from Python, through the Sample classes of samples/sample.h: lucent.render(name,
// scene=..., size=..., backend=..., **options) renders a sample as `lucent render --sample name`
// does and returns its linear RGB image as an (H, W, 4) float32 array (alpha 1); lucent.samples()
// lists the samples and their typed options. Options are the CLI's --set values: each keyword
// becomes "name=value" (True/False become 1/0), checked by the sample's own option declarations.
// ranks= spreads the render over MPI ranks as `mpirun lucent render` does (docs/distributed.md).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <utility>

#include "bindings.h"
#include "samples/sample.h"
#include "samples/settings_error.h"

namespace lucent::python {

float3 three_numbers(const py::handle& value, const std::string& what) {
    std::vector<double> v;
    try {
        v = value.cast<std::vector<double>>();
    } catch (const py::cast_error&) {
    }
    if (v.size() != 3)
        throw py::value_error(what + " must be three numbers (x, y, z); got " +
                              py::repr(value).cast<std::string>());
    return make_float3(float(v[0]), float(v[1]), float(v[2]));
}

namespace {

std::string option_text(const py::handle& value) {
    if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "1" : "0";
    if (py::isinstance<py::float_>(value)) return py::repr(value).cast<std::string>();
    return py::str(value).cast<std::string>();
}

/// A camera keyword (eye, look, up): None, or three numbers.
std::optional<float3> camera_point(const py::object& value, const char* name) {
    if (value.is_none()) return std::nullopt;
    return three_numbers(value, std::string("render: ") + name);
}

py::object render(const std::string& name, const std::optional<std::string>& scene,
                  std::pair<unsigned, unsigned> size, const std::string& backend, unsigned threads,
                  unsigned spp, int jit_check_sm, const py::object& eye, const py::object& look,
                  const py::object& up, std::optional<float> fov, std::optional<unsigned> camera,
                  bool denoise, unsigned denoise_passes,
                  const std::optional<std::vector<std::string>>& aovs, const py::object& devices,
                  const py::object& ranks, bool want_report, const py::kwargs& options) {
    samples::RenderSettings settings;
    settings.width = size.first;
    settings.height = size.second;
    if (settings.width == 0 || settings.height == 0 || settings.width > 16384 ||
        settings.height > 16384)
        throw py::value_error("render: size must be (width, height), each 1..16384; got (" +
                              std::to_string(size.first) + ", " + std::to_string(size.second) +
                              ")");
    settings.backend = backend_kind(backend, "render: backend");
    settings.threads = threads;
    settings.spp = spp;
    settings.jit_check_sm = jit_check_sm;
    if (scene) settings.scene = *scene;
    settings.camera.eye = camera_point(eye, "eye");
    settings.camera.look = camera_point(look, "look");
    settings.camera.up = camera_point(up, "up");
    settings.camera.fov_degrees = fov;  // checked with the rest of the camera by the sample
    settings.scene_camera = camera;     // the scene file's camera N (--camera N)
    for (const auto& [key, value] : options)
        settings.sets[key.cast<std::string>()] = option_text(value);
    settings.denoise = denoise;
    if (denoise_passes > 10)
        throw py::value_error("render: denoise_passes must be 0..10; got " +
                              std::to_string(denoise_passes));
    if (denoise_passes) settings.denoise_options.iterations = denoise_passes;
    settings.devices = device_list(devices);
    settings.ranks = ranks_argument(ranks, "render: ranks");
    samples::RenderResult result;
    try {
        const samples::Sample& sample = samples::find_sample(name);
        sample.read_options(settings);  // checked before the GIL is released
        if (aovs) {
            settings.aovs = samples::parse_aovs("aovs", *aovs);
            settings.alpha = true;
        }
        samples::check_aov_support(sample, settings);
        py::gil_scoped_release release;
        // Under ranks, a rank that fails (a scene file missing on one node) tells the others,
        // which would otherwise wait for it in the next launch; every rank raises RankError.
        run_agreed(settings.ranks, [&] { result = sample.render(settings); });
    } catch (const samples::SettingsError& e) {
        throw py::value_error(std::string("render: ") + e.what());
    }
    const scene::Image& image = result.image;
    py::array_t<float> rgba({py::ssize_t(image.height), py::ssize_t(image.width), py::ssize_t(4)});
    float* out = rgba.mutable_data();
    for (size_t i = 0; i < image.pixels.size(); ++i) {
        out[4 * i + 0] = image.pixels[i].x;
        out[4 * i + 1] = image.pixels[i].y;
        out[4 * i + 2] = image.pixels[i].z;
        out[4 * i + 3] = 1.0f;
    }
    // report=True: the LaunchReport of the sample's last launch comes last in a tuple.
    const auto with_report = [&](py::tuple answer) -> py::object {
        if (!want_report) return answer.size() == 1 ? answer[0] : py::object(answer);
        py::list items(answer);
        items.append(py::cast(result.report));
        return py::tuple(items);
    };
    if (!aovs) return with_report(py::make_tuple(rgba));
    // With aovs: alpha is the coverage, and the layers come as {channel: (H, W) array}.
    py::dict layers;
    for (const scene::ExrChannel& c : result.aovs) {
        if (c.name == "A") {
            for (size_t i = 0; i < c.values.size(); ++i) out[4 * i + 3] = c.values[i];
            continue;
        }
        py::array_t<float> values({py::ssize_t(image.height), py::ssize_t(image.width)});
        std::copy(c.values.begin(), c.values.end(), values.mutable_data());
        layers[py::str(c.name)] = values;
    }
    return with_report(py::make_tuple(rgba, layers));
}

const char* kind_name(samples::OptionKind kind) {
    switch (kind) {
        case samples::OptionKind::kInteger: return "integer";
        case samples::OptionKind::kNumber: return "number";
        case samples::OptionKind::kSwitch: return "switch";
        case samples::OptionKind::kText: break;
    }
    return "text";
}

/// An option's default as a Python value of its kind (int, float, bool or str).
py::object typed_default(const samples::SampleOption& o) {
    switch (o.kind) {
        case samples::OptionKind::kInteger: return py::int_(std::stoi(o.default_value));
        case samples::OptionKind::kNumber: return py::float_(std::stod(o.default_value));
        case samples::OptionKind::kSwitch: return py::bool_(o.default_value == "1");
        case samples::OptionKind::kText: break;
    }
    return py::str(o.default_value);
}

py::dict list_samples() {
    py::dict all;
    for (const samples::Sample* sample : samples::all_samples()) {
        py::dict options;
        for (const samples::SampleOption& o : sample->options) {
            py::dict option(py::arg("kind") = kind_name(o.kind),
                            py::arg("default") = typed_default(o), py::arg("help") = o.help);
            if (o.kind == samples::OptionKind::kInteger || o.kind == samples::OptionKind::kNumber)
                option["range"] = py::make_tuple(o.lo, o.hi);
            options[py::str(o.name)] = option;
        }
        all[py::str(sample->name)] =
            py::dict(py::arg("description") = sample->description, py::arg("options") = options);
    }
    return all;
}

}  // namespace

void bind_samples(py::module_& m) {
    m.def("render", &render, py::arg("sample"), py::kw_only(), py::arg("scene") = py::none(),
          py::arg("size") = std::pair<unsigned, unsigned>{512, 512}, py::arg("backend") = "auto",
          py::arg("threads") = 0u, py::arg("spp") = 0u, py::arg("jit_check_sm") = 0,
          py::arg("eye") = py::none(), py::arg("look") = py::none(), py::arg("up") = py::none(),
          py::arg("fov") = py::none(), py::arg("camera") = py::none(), py::arg("denoise") = false,
          py::arg("denoise_passes") = 0u, py::arg("aovs") = py::none(),
          py::arg("devices") = py::none(), py::arg("ranks") = py::none(),
          py::arg("report") = false,
          "Renders a sample as `lucent render --sample NAME` does: scene (a built-in name or a "
          "file; None: the sample's own), size (width, height), backend, CPU threads, spp "
          "(progressive samples; 0: the sample's default), the camera's eye, look, up (x, y, z) "
          "and vertical fov in degrees over the scene's (--eye --look --up --fov; each "
          "None: the scene's), camera N of the scene file's own (a glTF file's cameras, "
          "--camera N; None: its first), and the sample's options as "
          "keywords (vpls=64). denoise=True filters the image with the edge-avoiding "
          "à-trous denoiser (--denoise; denoise_passes as --denoise-passes). Returns the "
          "linear RGB image as an (H, W, 4) float32 array, row 0 at the top, alpha 1; with "
          "aovs=['albedo', 'normal', 'depth', 'position', 'instance'] (any of them, --aov) "
          "returns (image, layers): alpha is the coverage and layers maps each EXR channel "
          "name ('Albedo.R', 'Nx', 'Z', ...) to an (H, W) float32 array. devices='0,1' (or "
          "['cpu', 'cpu'], --devices) spreads every launch over those devices, with the "
          "image of one (docs/multi-device.md). ranks=lucent.Ranks."
          "world() under mpirun spreads every launch over the ranks (every rank calls render "
          "alike and gets the whole image, the image of one process; a rank's failure is "
          "every rank's lucent.RankError; docs/distributed.md). report=True also returns the "
          "LaunchReport of the sample's last launch, last: (image, report) or (image, "
          "layers, report).");
    m.def("samples", &list_samples,
          "{name: {'description': ..., 'options': {option: {'kind': 'integer'|'number'|'switch'|'text', "
          "'default': ..., 'help': ..., 'range': (lo, hi) for numbers and integers}}}}");
}

}  // namespace lucent::python

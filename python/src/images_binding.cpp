// Images from Python: lucent.read_image(path) and lucent.compare(reference, test), as
// `lucent compare` (scene/image_compare.h) reads and compares them.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <optional>
#include <string>

#include "array_args.h"
#include "bindings.h"
#include "scene/image_compare.h"
#include "scene/image_read.h"

namespace lucent::python {

namespace {

py::array_t<float> image_array(const scene::Image& image) {
    py::array_t<float> out({py::ssize_t(image.height), py::ssize_t(image.width), py::ssize_t(3)});
    std::memcpy(out.mutable_data(), image.pixels.data(), image.pixels.size() * sizeof(float3));
    return out;
}

/// A path (str or os.PathLike: read as `lucent compare` reads it) or an (H, W, 3) or
/// (H, W, 4) float array of linear RGB (alpha ignored).
scene::Image image_argument(const py::handle& value, const char* name) {
    const py::module_ os = py::module_::import("os");
    if (py::isinstance<py::str>(value) || py::isinstance(value, os.attr("PathLike"))) {
        const std::string path = py::str(os.attr("fspath")(value));
        py::gil_scoped_release release;
        return scene::read_image(path);
    }
    if (!py::isinstance<py::array>(value))
        throw py::type_error(std::string("compare: ") + name +
                             " must be a file path or an (H, W, 3) or (H, W, 4) float array; got " +
                             py::repr(value).cast<std::string>());
    const py::array a = py::reinterpret_borrow<py::array>(value);
    if (a.dtype().kind() != 'f')
        throw py::type_error(std::string("compare: ") + name +
                             " must be a float array (linear RGB); got " + describe_array(a));
    if (a.ndim() != 3 || (a.shape(2) != 3 && a.shape(2) != 4) || a.shape(0) == 0 || a.shape(1) == 0)
        throw py::value_error(std::string("compare: ") + name +
                              " must be an (H, W, 3) or (H, W, 4) array; got " + describe_array(a));
    const auto f = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
    scene::Image image;
    image.height = unsigned(a.shape(0));
    image.width = unsigned(a.shape(1));
    const size_t channels = size_t(a.shape(2));
    const float* p = f.data();
    image.pixels.resize(size_t(image.width) * image.height);
    for (size_t i = 0; i < image.pixels.size(); ++i, p += channels)
        image.pixels[i] = make_float3(p[0], p[1], p[2]);
    return image;
}

py::dict compare(const py::handle& reference, const py::handle& test, std::optional<double> ppd) {
    const scene::Image r = image_argument(reference, "reference");
    const scene::Image t = image_argument(test, "test");
    if (ppd && !(*ppd >= 1.0 && *ppd <= 1000.0))
        throw py::value_error("compare: ppd must be in [1, 1000] pixels per degree; got " +
                              std::to_string(*ppd));
    scene::ImageComparison c;
    {
        py::gil_scoped_release release;
        c = scene::compare_images(r, t, ppd.value_or(scene::kFlipPixelsPerDegree));
    }
    py::array_t<float> flip({py::ssize_t(c.height), py::ssize_t(c.width)});
    std::memcpy(flip.mutable_data(), c.flip.data(), c.flip.size() * sizeof(float));
    return py::dict(py::arg("rmse") = c.rmse, py::arg("relmse") = c.relmse,
                    py::arg("psnr_db") = c.psnr_db, py::arg("flip_mean") = c.flip_mean,
                    py::arg("flip_median") = c.flip_median, py::arg("flip_max") = c.flip_max,
                    py::arg("flip") = flip);
}

}  // namespace

void bind_images(py::module_& m) {
    m.def(
        "read_image",
        [](const py::handle& path) {
            return image_array(image_argument(path, "path"));
        },
        py::arg("path"),
        "Reads .exr, .pfm, .hdr (linear) or .png, .jpg, .bmp, .tga (decoded from sRGB) as an "
        "(H, W, 3) float32 array of linear RGB, row 0 at the top.");
    m.def("compare", &compare, py::arg("reference"), py::arg("test"), py::kw_only(),
          py::arg("ppd") = py::none(),
          "Compares a test image with a reference as `lucent compare` does. Each is a file path "
          "or an (H, W, 3) or (H, W, 4) float array of linear RGB. ppd: FLIP's pixels per "
          "degree (default 67.0: a 0.7 m wide 4K monitor seen from 0.7 m). Returns {'rmse', "
          "'relmse', 'psnr_db' (inf: identical), 'flip_mean', 'flip_median', 'flip_max', "
          "'flip': the (H, W) float32 FLIP map}.");
}

}  // namespace lucent::python

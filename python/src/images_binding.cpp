// Images from Python: lucent.read_image(path) and lucent.compare(reference, test), as
// `lucent compare` (scene/image_compare.h) reads and compares them, and
// lucent.write_image(path, image, layers), as `lucent render --out` writes its images.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <optional>
#include <string>

#include "array_args.h"
#include "bindings.h"
#include "scene/exr_encoder.h"
#include "scene/image_compare.h"
#include "scene/image_io.h"
#include "scene/image_read.h"

namespace lucent::python {

namespace {

py::array_t<float> image_array(const scene::Image& image) {
    py::array_t<float> out({py::ssize_t(image.height), py::ssize_t(image.width), py::ssize_t(3)});
    std::memcpy(out.mutable_data(), image.pixels.data(), image.pixels.size() * sizeof(float3));
    return out;
}

/// A float array as numpy gives it, converted to C-ordered float32 where it is not.
using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

/// An (H, W, 3) or (H, W, 4) float array of linear RGB; a TypeError or ValueError "<call>:
/// <name> must be ..." otherwise. The 4th channel goes to `alpha` when it is given (an
/// (H, W, 3) image is then a ValueError), and is ignored when not.
scene::Image image_from_array(const py::handle& value, const std::string& call, const char* name,
                              std::vector<float>* alpha = nullptr) {
    if (!py::isinstance<py::array>(value))
        throw py::type_error(call + ": " + name +
                             " must be an (H, W, 3) or (H, W, 4) float array; got " +
                             py::repr(value).cast<std::string>());
    const py::array a = py::reinterpret_borrow<py::array>(value);
    if (a.dtype().kind() != 'f')
        throw py::type_error(call + ": " + name + " must be a float array (linear RGB); got " +
                             describe_array(a));
    if (a.ndim() != 3 || (a.shape(2) != 3 && a.shape(2) != 4) || a.shape(0) == 0 || a.shape(1) == 0)
        throw py::value_error(call + ": " + name +
                              " must be an (H, W, 3) or (H, W, 4) array; got " + describe_array(a));
    const size_t channels = size_t(a.shape(2));
    if (alpha && channels != 4)
        throw py::value_error(call + ": alpha=True needs an (H, W, 4) " + name + "; got " +
                              describe_array(a));
    const auto f = FloatArray::ensure(a);
    scene::Image image;
    image.height = unsigned(a.shape(0));
    image.width = unsigned(a.shape(1));
    const float* p = f.data();
    image.pixels.resize(size_t(image.width) * image.height);
    if (alpha) alpha->resize(image.pixels.size());
    for (size_t i = 0; i < image.pixels.size(); ++i, p += channels) {
        image.pixels[i] = make_float3(p[0], p[1], p[2]);
        if (alpha) (*alpha)[i] = p[3];
    }
    return image;
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
    return image_from_array(value, "compare", name);
}

/// Writes `image` (and, to an .exr, `layers`: {channel name: (H, W) float array}, as
/// render(aovs=...) returns them, and with `alpha` its 4th channel as A) through
/// scene::write_image: a temporary file renamed into place, so a failure leaves no partial
/// file.
void write_image(const py::object& path, const py::handle& image, const py::object& layers,
                 bool alpha) {
    const std::string file = path_argument(path, "write_image", "path", "an image file's path");
    // With alpha, the coverage render(aovs=...) returns in the 4th channel becomes the EXR's
    // A channel, as `lucent render --aov` writes it.
    std::vector<float> coverage;
    const scene::Image pixels =
        image_from_array(image, "write_image", "image", alpha ? &coverage : nullptr);
    scene::ExrExtras extras;
    if (alpha) extras.channels.push_back({"A", std::move(coverage)});
    if (!layers.is_none()) {
        if (!py::isinstance<py::dict>(layers))
            throw py::type_error("write_image: layers must be a dict {channel name: (H, W) float "
                                 "array}, as render(aovs=...) returns; got " +
                                 py::repr(layers).cast<std::string>());
        for (const auto& [key, value] : layers.cast<py::dict>()) {
            const std::string name = py::str(key).cast<std::string>();
            const auto a = FloatArray::ensure(value);
            if (!a || a.ndim() != 2 || size_t(a.shape(0)) != pixels.height ||
                size_t(a.shape(1)) != pixels.width)
                throw py::value_error("write_image: layer '" + name + "' must be a (" +
                                      std::to_string(pixels.height) + ", " +
                                      std::to_string(pixels.width) +
                                      ") float array, the image's height and width; got " +
                                      py::repr(value).cast<std::string>());
            extras.channels.push_back({name, std::vector<float>(a.data(), a.data() + a.size())});
        }
    }
    py::gil_scoped_release release;
    scene::write_image(file, pixels, extras);
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
    m.def("write_image", &write_image, py::arg("path"), py::arg("image"), py::kw_only(),
          py::arg("layers") = py::none(), py::arg("alpha") = false,
          "Writes an (H, W, 3) or (H, W, 4) float array of linear RGB (row 0 at the top; "
          "alpha dropped) as `lucent render --out` does, by the path's extension: .png (8-bit "
          "sRGB), .pfm (32-bit float) or .exr (OpenEXR, float), through a temporary file, so "
          "that a failure leaves no partial file. layers ({channel: (H, W) array}, as "
          "render(aovs=...) returns) go into an .exr beside R, G, B, and with alpha=True the "
          "image's 4th channel as A (the coverage render(aovs=...) returns).");
    m.def("compare", &compare, py::arg("reference"), py::arg("test"), py::kw_only(),
          py::arg("ppd") = py::none(),
          "Compares a test image with a reference as `lucent compare` does. Each is a file path "
          "or an (H, W, 3) or (H, W, 4) float array of linear RGB. ppd: FLIP's pixels per "
          "degree (default 67.0: a 0.7 m wide 4K monitor seen from 0.7 m). Returns {'rmse', "
          "'relmse', 'psnr_db' (inf: identical), 'flip_mean', 'flip_median', 'flip_max', "
          "'flip': the (H, W) float32 FLIP map}.");
}

}  // namespace lucent::python

// TEA from Python, as the CLI's `lucent tea` and `lucent noise` give it: lucent.tea encrypts
// one block (Sebald §3.2: the fog sample's random numbers), lucent.tea_statistics measures
// the output's quality against the round count, and lucent.noise makes the white, gradient
// and spectrum noise images (Sebald Figures 5-7) as arrays.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "lucent/device/tea.h"
#include "samples/tea/tea_noise.h"
#include "samples/tea/tea_statistics.h"

namespace lucent::python {

namespace {

/// `words` as `count` 32-bit words (Python or numpy integers, any size: compared as Python
/// integers); a ValueError naming `what` otherwise.
std::vector<unsigned> words_of(const py::handle& words, size_t count, const char* what) {
    std::vector<unsigned> out;
    const auto refuse = [&] {
        return py::value_error(std::string(what) + " must be " + std::to_string(count) +
                               " integers in [0, 2**32); got " +
                               py::repr(words).cast<std::string>());
    };
    if (!py::isinstance<py::sequence>(words) || py::isinstance<py::str>(words)) throw refuse();
    for (const py::handle& w : words) {
        if (py::isinstance<py::bool_>(w) || !PyIndex_Check(w.ptr())) throw refuse();
        const auto n = py::reinterpret_steal<py::int_>(PyNumber_Index(w.ptr()));
        if (!n) throw py::error_already_set();
        if (n < py::int_(0) || n > py::int_(0xffffffffu)) throw refuse();
        out.push_back(n.cast<unsigned>());
    }
    if (out.size() != count) throw refuse();
    return out;
}

void check_rounds(unsigned rounds, const char* what) {
    if (rounds < 1 || rounds > 64)
        throw py::value_error(std::string(what) +
                              ": rounds must be 1..64 (32 is the cipher); got " +
                              std::to_string(rounds));
}

py::tuple tea_block(const py::object& block, const py::object& key, unsigned rounds) {
    check_rounds(rounds, "tea");
    const std::vector<unsigned> v = words_of(block, 2, "tea: block");
    const std::vector<unsigned> k = words_of(key, 4, "tea: key");
    const uint2 out = tea(make_uint2(v[0], v[1]), make_uint4(k[0], k[1], k[2], k[3]), rounds);
    return py::make_tuple(out.x, out.y);
}

py::list tea_statistics(const std::vector<unsigned>& rounds, unsigned blocks) {
    if (blocks < 1000 || blocks > (1u << 26))
        throw py::value_error("tea_statistics: blocks must be 1000..2**26; got " +
                              std::to_string(blocks));
    if (rounds.empty()) throw py::value_error("tea_statistics: rounds is empty");
    for (unsigned r : rounds) check_rounds(r, "tea_statistics");
    std::vector<samples::TeaStatistics> rows;
    {
        py::gil_scoped_release release;
        for (unsigned r : rounds) rows.push_back(samples::measure_tea(r, zafar_tea_key(), blocks));
    }
    py::list out;
    for (const samples::TeaStatistics& s : rows)
        out.append(py::dict(
            py::arg("rounds") = s.rounds, py::arg("bytes") = s.bytes,
            py::arg("ones_fraction") = s.ones_fraction, py::arg("bit_balance_z") = s.bit_balance_z,
            py::arg("byte_chi_square") = s.byte_chi_square,
            py::arg("chi_square_p") = s.chi_square_p,
            py::arg("serial_correlation") = s.serial_correlation, py::arg("passes") = s.passes()));
    return out;
}

py::array_t<float> noise(const std::string& kind, std::optional<unsigned> size, unsigned rounds,
                         std::optional<unsigned long long> seed, unsigned device) {
    check_rounds(rounds, "noise");
    if (kind != "white" && kind != "gradient" && kind != "spectrum")
        throw py::value_error(
            "noise: kind is '" + kind +
            "'; use 'white', 'gradient' or 'spectrum' (as `lucent noise --kind`)");
    if (size && (*size < 8 || *size > 4096))
        throw py::value_error("noise: size must be 8..4096 pixels a side; got " +
                              std::to_string(*size));
    if (seed && *seed > 0xffffffffull)
        throw py::value_error("noise: seed must be in [0, 2**32); got " + std::to_string(*seed));
    // With a seed, the per-device key of Sebald Fig. 4; without, Zafar et al.'s fixed key.
    const uint4 key = seed ? generate_tea_key(zafar_tea_key(), make_uint2(device, unsigned(*seed)))
                           : zafar_tea_key();
    scene::Image image;
    {
        py::gil_scoped_release release;
        if (kind == "white")
            image = samples::white_noise(size.value_or(64), size.value_or(64), rounds, key);
        else if (kind == "gradient")
            image =
                samples::gradient_noise(size.value_or(256), size.value_or(256), 32, rounds, key);
        else
            image = samples::noise_spectrum(size.value_or(1024), rounds, key);
    }
    // The images are gray: one channel of each pixel, row 0 at the top.
    py::array_t<float> values({py::ssize_t(image.height), py::ssize_t(image.width)});
    float* out = values.mutable_data();
    for (size_t i = 0; i < image.pixels.size(); ++i) out[i] = image.pixels[i].x;
    return values;
}

}  // namespace

void bind_tea(py::module_& m) {
    m.def("tea", &tea_block, py::arg("block"), py::arg("key"), py::arg("rounds") = 32u,
          "Encrypts one 64-bit block (two 32-bit words) with TEA under a 128-bit key (four "
          "words) in `rounds` rounds (1..64; 32 is the cipher), as `lucent tea --block --key "
          "--rounds`; returns the two output words. tea((0, 0), (0, 0, 0, 0)) is (0x41ea3a0a, "
          "0x94baa940).");
    m.def("tea_statistics", &tea_statistics,
          py::arg("rounds") = std::vector<unsigned>{1, 2, 3, 4, 5, 6, 8, 16, 32},
          py::arg("blocks") = 1u << 20,
          "The quality of TEA's output against the round count, as `lucent tea --statistics`: "
          "for each round count, `blocks` counter blocks encrypted with Zafar et al.'s key and "
          "their bytes measured (bit balance, byte chi-square and its p, serial correlation, "
          "and whether all are inside their bounds); a list of dicts, one per round count.");
    m.def("noise", &noise, py::arg("kind") = "white", py::kw_only(), py::arg("size") = py::none(),
          py::arg("rounds") = 4u, py::arg("seed") = py::none(), py::arg("device") = 0u,
          "A TEA noise image as `lucent noise` writes it (Sebald Figures 5-7), as an (H, W) "
          "float32 array in [0, 1], row 0 at the top: 'white' (64x64 by default), 'gradient' "
          "(one octave on 32-pixel cells, 256x256) or 'spectrum' (the centred log power "
          "spectrum of white noise, 1024x1024; needs FFTW). size is the side (8..4096); with "
          "a seed the key is the per-device key of (device, seed), else the fixed key.");
}

}  // namespace lucent::python

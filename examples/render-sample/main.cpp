// Renders one of Lucent's samples from a program of your own, as `lucent render` does: the
// sample is found by name, its options are set as `--set name=value` sets them, and the
// image comes back as linear RGB floats, here written as a PNG (or .exr, .pfm).
//
//   render-sample [--sample NAME] [--scene NAME|FILE] [--size WxH] [--set NAME=VALUE]...
//                 [--backend cpu|cuda|auto] [--jit-check SM] [--out FILE.png] [--list]
//
// The defaults are the README's main job: Instant Global Illumination with 64 VPLs on the
// built-in Cornell box, 512x512; another --sample starts from its own scene and options.
// --list prints every sample with its options.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "lucent/lucent.h"
#include "samples/sample.h"
#include "samples/settings_error.h"
#include "scene/image_io.h"

namespace {

struct Arguments {
    std::string sample = "igi";
    std::string out = "render-sample.png";
    bool list = false;
    lucent::samples::RenderSettings settings;
};

void usage() {
    std::fprintf(stderr,
                 "usage: render-sample [--sample NAME] [--scene NAME|FILE] [--size WxH] "
                 "[--set NAME=VALUE]... [--backend cpu|cuda|auto] [--jit-check SM] "
                 "[--out FILE.png] [--list]\n");
}

/// Parses the command line; false (after saying why) on a bad argument. The sample and its
/// --set values are checked by the sample itself when it renders.
bool parse_args(int argc, char** argv, Arguments& a) {
    using lucent::BackendKind;
    lucent::samples::RenderSettings& s = a.settings;
    s.width = s.height = 512;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--list") {
            a.list = true;
            continue;
        }
        const std::string value = i + 1 < argc ? argv[++i] : "";
        unsigned w = 0, h = 0;
        char end = 0;
        if (flag == "--sample" && !value.empty()) {
            a.sample = value;
        } else if (flag == "--scene" && !value.empty()) {
            s.scene = value;
        } else if (flag == "--size" && std::sscanf(value.c_str(), "%ux%u%c", &w, &h, &end) == 2 &&
                   w > 0 && h > 0 && w <= 16384 && h <= 16384) {
            s.width = w, s.height = h;
        } else if (flag == "--set" && value.find('=') != std::string::npos && value.find('=') > 0) {
            s.sets[value.substr(0, value.find('='))] = value.substr(value.find('=') + 1);
        } else if (flag == "--backend" && (value == "cpu" || value == "cuda" || value == "auto")) {
            s.backend = value == "cpu"    ? BackendKind::kCpu
                        : value == "cuda" ? BackendKind::kCuda
                                          : BackendKind::kAuto;
        } else if (flag == "--jit-check" && std::atoi(value.c_str()) > 0) {
            s.jit_check_sm = std::atoi(value.c_str());  // e.g. 90: sm_90
        } else if (flag == "--out" && !value.empty()) {
            a.out = value;
        } else {
            std::fprintf(stderr, "render-sample: bad argument '%s%s%s'\n", flag.c_str(),
                         value.empty() ? "" : " ", value.c_str());
            usage();
            return false;
        }
    }
    // The main job: IGI on the Cornell box with 64 VPLs unless told otherwise; another
    // sample starts from its own scene and defaults.
    if (a.sample == "igi") {
        if (s.scene.empty()) s.scene = "cornell";
        if (s.sets.empty()) s.sets["vpls"] = "64";
    }
    return true;
}

/// Every sample and its options, as `lucent render --help` lists them.
void list_samples() {
    for (const lucent::samples::Sample* sample : lucent::samples::all_samples()) {
        std::printf("%s: %s\n", sample->name.c_str(), sample->description.c_str());
        for (const lucent::samples::SampleOption& o : sample->options)
            std::printf("    --set %s=%s  %s%s%s\n", o.name.c_str(), o.default_value.c_str(),
                        o.help.c_str(), o.range().empty() ? "" : " ", o.range().c_str());
    }
}

}  // namespace

int main(int argc, char** argv) {
    Arguments a;
    if (!parse_args(argc, argv, a)) return 2;
    if (a.list) {
        list_samples();
        return 0;
    }
    try {
        // A name that is no sample, or an option it does not have or a value out of its
        // range, is a SettingsError naming it and what is accepted.
        const lucent::samples::Sample& sample = lucent::samples::find_sample(a.sample);
        const auto start = std::chrono::steady_clock::now();
        const lucent::samples::RenderResult result = sample.render(a.settings);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        if (a.settings.jit_check_sm)
            std::printf("jit-check: megakernel compiled for sm_%d in %.0f ms%s\n",
                        a.settings.jit_check_sm, result.report.jit_ms,
                        result.report.jit_cached ? " (from the cache)" : "");
        double sum = 0;
        for (const float3& p : result.image.pixels) sum += (p.x + p.y + p.z) / 3.0;
        std::printf("backend: %s\n", result.backend.c_str());
        std::printf("sample: %s on %s, %ux%u\n", sample.name.c_str(),
                    a.settings.scene.empty() ? "its own scene" : a.settings.scene.c_str(),
                    result.image.width, result.image.height);
        std::printf("mean value %.4f\n",
                    result.image.pixels.empty() ? 0.0 : sum / result.image.pixels.size());
        for (const lucent::samples::StageTiming& stage : result.stages)
            std::printf("  %-24s %9.3f ms %s\n", stage.name.c_str(), stage.ms, stage.note.c_str());
        std::printf("render %.1f ms (with the scene's set-up)\n", ms);
        lucent::scene::write_image(a.out, result.image);
        std::printf("wrote %s\n", a.out.c_str());
    } catch (const lucent::samples::SettingsError& e) {
        std::fprintf(stderr, "render-sample: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "render-sample: %s\n", e.what());
        return 1;
    }
    return 0;
}

// `lucent render`: checks every input before the (long) render, so a typo fails at once and
// never leaves a file behind; write_image itself is atomic.
#include "render_command.h"

#include <cstdio>
#include <sstream>

#include "cli_parse.h"
#include "progress_bar.h"
#include "samples/sample.h"
#include "samples/stages.h"

namespace lucent::cli {
namespace {

using samples::Clock;
using samples::ms_since;

/// Breaks `text` into lines of at most kHelpWidth columns; the first line starts at column
/// `first`, the others are indented by `indent`.
std::string wrap(const std::string& text, size_t first, size_t indent) {
    constexpr size_t kHelpWidth = 90;
    std::istringstream words(text);
    std::string out, word;
    size_t column = first;
    bool line_start = true;
    while (words >> word) {
        if (!line_start && column + 1 + word.size() > kHelpWidth) {
            out += "\n" + std::string(indent, ' ');
            column = indent;
            line_start = true;
        }
        if (!line_start) {
            out += ' ';
            ++column;
        }
        out += word;
        column += word.size();
        line_start = false;
    }
    return out;
}

/// The samples and their --set options, for `render --help`.
std::string samples_help() {
    std::ostringstream out;
    out << "Samples (--sample NAME) and their options (--set NAME=VALUE, default shown):\n";
    for (const samples::Sample* sample : samples::all_samples()) {
        out << "  " << sample->name << "  " << wrap(sample->description, 4 + sample->name.size(), 4)
            << "\n";
        size_t width = 0;
        for (const samples::SampleOption& o : sample->options)
            width = std::max(width, o.name.size() + 1 + o.default_value.size());
        for (const samples::SampleOption& o : sample->options) {
            const std::string set = o.name + "=" + o.default_value;
            out << "    " << set << std::string(width - set.size() + 2, ' ') << o.help_with_range()
                << "\n";
        }
        if (sample->options.empty()) out << "    (no options)\n";
    }
    return out.str();
}

samples::RenderSettings settings_from(const RenderArgs& args) {
    samples::RenderSettings s;
    const Size size = parse_size("--size", args.size);
    s.width = size.width;
    s.height = size.height;
    s.backend = parse_backend("--backend", args.backend);
    s.devices = parse_devices("--devices", args.devices);
    s.threads = args.threads;
    s.scene = args.scene;
    s.verbose = args.verbose;
    if (!args.jit_check.empty()) s.jit_check_sm = parse_sm("--jit-check", args.jit_check);
    s.repeat = args.repeat;
    s.spp = args.spp;
    for (const std::string& text : args.sets) {
        auto [name, value] = parse_set("--set", text);
        s.sets[name] = value;  // a later --set of the same name wins, as in most CLIs
    }
    return s;
}

}  // namespace

CLI::App* add_render_command(CLI::App& app, RenderArgs& args) {
    CLI::App* cmd = app.add_subcommand("render", "Render a sample's scene and write the image");
    cmd->add_option("--sample", args.sample, "Sample to run (listed below)")
        ->type_name("NAME")
        ->capture_default_str();
    cmd->add_option("--size", args.size, "Image size, each side 1..16384")
        ->type_name("WxH")
        ->capture_default_str();
    cmd->add_option("-o,--out", args.out,
                    "Output image: .png (8-bit sRGB), .exr or .pfm (linear float)")
        ->type_name("FILE")
        ->capture_default_str();
    cmd->add_option("--backend", args.backend, "auto, cpu or cuda")
        ->type_name("KIND")
        ->capture_default_str();
    add_devices_option(cmd, args.devices);
    cmd->add_option("--scene", args.scene,
                    "Built-in scene or scene file (default: the sample's own)")
        ->type_name("NAME|FILE");
    cmd->add_option("--set", args.sets, "Sample option (repeatable)")->type_name("NAME=VALUE");
    cmd->add_option("--threads", args.threads, "CPU worker threads, 0 = one per core")
        ->type_name("N")
        ->check(CLI::Range(0u, 4096u).description(""))
        ->capture_default_str();
    cmd->add_flag("-v,--verbose", args.verbose,
                  "Print the settings and the sample's options before rendering");
    cmd->add_option("--repeat", args.repeat,
                    "Launch this many times and report the median launch time and frames/s")
        ->type_name("N")
        ->check(CLI::Range(1u, 100000u).description(""))
        ->capture_default_str();
    cmd->add_option("--spp", args.spp,
                    "Samples per pixel of a progressive sample (the path tracer), one launch "
                    "each; 0 = the sample's default")
        ->type_name("N")
        ->check(CLI::Range(0u, 1000000u).description(""))
        ->capture_default_str();
    cmd->add_option("--jit-check", args.jit_check,
                    "Also generate the CUDA megakernel and compile it with NVRTC for this GPU "
                    "architecture (works without a GPU)")
        ->type_name("sm_XY");
    cmd->footer(samples_help() +
                "\nExamples:\n"
                "  lucent render --sample whitted --size 1024x1024 --out whitted.png\n"
                "  lucent render --size 640x480 --threads 2 --out quick.png\n"
                "  lucent render --out whitted.exr      # linear float image (or .pfm)\n"
                "  lucent render --backend cuda         # on the GPU; a clear error without one\n"
                "  lucent render --repeat 500           # median launch time and frames/s\n"
                "  lucent render --jit-check sm_90      # also compile the GPU megakernel\n"
                "  lucent render --sample pathtracer --scene cornell-materials --spp 256\n");
    return cmd;
}

int run_render(const RenderArgs& args) {
    const samples::RenderSettings settings = settings_from(args);
    check_image_path("--out", args.out);
    const samples::Sample& sample = samples::find_sample(args.sample);
    sample.read_options(settings);  // every --set checked before the render
    if (args.verbose) {
        std::printf("sample %s, %ux%u, backend %s, threads %u, scene %s\n", sample.name.c_str(),
                    settings.width, settings.height, args.backend.c_str(), settings.threads,
                    settings.scene.empty() ? "(default)" : settings.scene.c_str());
        for (const auto& [name, value] : settings.sets)
            std::printf("  --set %s=%s\n", name.c_str(), value.c_str());
    }

    ProgressBar bar("render", "launches");
    samples::RenderSettings run = settings;
    run.progress = [&bar](unsigned done, unsigned total) { bar.update(done, total); };
    const Clock::time_point start = Clock::now();
    samples::RenderResult result = sample.render(run);
    bar.finish();
    const Clock::time_point written = Clock::now();
    scene::write_image(args.out, result.image);
    const double write_ms = ms_since(written);
    const double total_ms = ms_since(start);

    if (!result.backend_notice.empty()) std::printf("note: %s\n", result.backend_notice.c_str());
    std::printf("%s: %ux%u on %s\n", sample.name.c_str(), result.image.width, result.image.height,
                result.backend.c_str());

    for (const samples::StageTiming& stage : result.stages)
        std::printf("  %-20s %10.3f ms%s%s\n", stage.name.c_str(), stage.ms,
                    stage.note.empty() ? "" : "  ", stage.note.c_str());
    std::printf("  %-20s %10.3f ms\n", "write image", write_ms);
    std::printf("  %-20s %10.3f ms (wall clock)\n", "total", total_ms);
    if (result.report.exception_count() > 0) {
        std::string summary = result.report.summary();
        if (!summary.empty() && summary.back() != '\n') summary += '\n';
        std::printf("exceptions (%llu in all):\n%s",
                    (unsigned long long)result.report.exception_count(), summary.c_str());
    }
    std::printf("wrote %s\n", args.out.c_str());
    return 0;
}

}  // namespace lucent::cli

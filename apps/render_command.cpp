// `lucent render`: checks every input before the (long) render, so a typo fails at once and
// never leaves a file behind; write_image itself is atomic.
#include "render_command.h"

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include <nlohmann/json.hpp>

#include "camera_flags.h"
#include "cli_ranks.h"
#include "cli_parse.h"
#include "progress_bar.h"
#include "samples/sample.h"
#include "samples/stages.h"
#include "scene/exr_encoder.h"

namespace lucent::cli {
namespace {

using samples::Clock;
using samples::ms_since;
using Json = nlohmann::ordered_json;

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
    if (args.camera >= 0) s.scene_camera = unsigned(args.camera);
    s.camera = parse_camera_flags(args.camera_flags);
    s.repeat = args.repeat;
    s.spp = args.spp;
    if (!args.aov.empty() || args.aov_given) s.aovs = samples::parse_aovs("--aov", args.aov);
    s.denoise = args.denoise;
    if (args.denoise_passes) s.denoise_options.iterations = args.denoise_passes;
    for (const std::string& text : args.sets) {
        auto [name, value] = parse_set("--set", text);
        s.sets[name] = value;  // a later --set of the same name wins, as in most CLIs
    }
    return s;
}

/// The render's progress on a terminal (stderr): the launches done of several (a
/// progressive sample, --repeat), or else the rows done of the one launch, which the CPU
/// backend reports in bands as they finish.
class RenderProgress {
  public:
    explicit RenderProgress(bool wanted) : m_wanted(wanted) {}
    bool shown() const { return m_wanted && m_rows.enabled(); }
    void launches(unsigned done, unsigned total) {
        if (!m_wanted) return;
        m_several = m_several || total > 1;
        m_load.finish();
        m_rows.finish();
        m_launches.update(done, total);
    }
    /// A scene file being read: shown for loads over a second, in MB (10^6 bytes).
    void load(const std::string& stage, uint64_t done, uint64_t total) {
        if (!m_wanted) return;
        m_load.set_label(stage);
        m_load.update(done / 1000000, total / 1000000);
    }
    void rows(const LaunchProgress& p) {
        if (!m_wanted || m_several) return;
        m_load.finish();
        m_rows.update(p.rows_done, p.rows);
    }
    void finish() {
        m_load.finish();
        m_rows.finish();
        m_launches.finish();
    }

  private:
    bool m_wanted;
    bool m_several = false;
    ProgressBar m_rows{"render", "rows"}, m_launches{"render", "launches"};
    ProgressBar m_load{"load", "MB", std::chrono::seconds(1)};
};

/// `render --json`: the settings asked for, where it ran, and the stages' times.
Json render_json(const RenderArgs& args, const samples::RenderSettings& settings,
                 const samples::Sample& sample, const samples::RenderResult& result,
                 double write_ms, double total_ms) {
    Json j;
    j["sample"] = sample.name;
    j["width"] = result.image.width;
    j["height"] = result.image.height;
    j["backend"] = result.backend;
    if (!result.backend_notice.empty()) j["backend_notice"] = result.backend_notice;
    j["scene"] = settings.scene.empty() ? Json(nullptr) : Json(settings.scene);
    j["sets"] = Json::object();
    for (const auto& [name, value] : settings.sets) j["sets"][name] = value;
    j["spp"] = settings.spp;
    j["repeat"] = settings.repeat;
    j["threads"] = settings.threads;
    j["aovs"] = Json::array();
    for (const scene::ExrChannel& c : result.aovs) j["aovs"].push_back(c.name);
    j["denoise"] = settings.denoise;
    if (settings.denoise) j["denoise_passes"] = settings.denoise_options.iterations;
    Json camera = Json::object();
    auto vec = [](float3 v) { return Json::array({v.x, v.y, v.z}); };
    if (settings.camera.eye) camera["eye"] = vec(*settings.camera.eye);
    if (settings.camera.look) camera["look"] = vec(*settings.camera.look);
    if (settings.camera.up) camera["up"] = vec(*settings.camera.up);
    if (settings.camera.fov_degrees) camera["fov"] = *settings.camera.fov_degrees;
    if (settings.scene_camera) camera["index"] = *settings.scene_camera;  // --camera N
    j["camera"] = camera;
    if (result.camera)
        j["rendered_camera"] = {{"eye", vec(result.camera->eye)},
                                {"look", vec(result.camera->look)},
                                {"up", vec(result.camera->up)},
                                {"fov", result.camera->fov_degrees}};
    j["stages"] = Json::array();
    for (const samples::StageTiming& stage : result.stages)
        j["stages"].push_back({{"name", stage.name}, {"ms", stage.ms}, {"note", stage.note}});
    j["write_ms"] = write_ms;
    j["total_ms"] = total_ms;
    j["exceptions"] = result.report.exception_count();
    if (result.report.exception_count() > 0) j["exception_summary"] = result.report.summary();
    j["out"] = args.out;
    return j;
}

/// The EXR header's metadata: the render's JSON whole ("lucent.render": settings, stages and
/// times but the write's) and its most wanted parts on their own, as string attributes.
std::vector<std::pair<std::string, std::string>> exr_metadata(const Json& render) {
    std::vector<std::pair<std::string, std::string>> out = {
        {"software", "Lucent"},
        {"lucent.sample", render["sample"].get<std::string>()},
        {"lucent.spp", std::to_string(render["spp"].get<unsigned>())},
        {"lucent.sets", render["sets"].dump()},
        {"lucent.denoise", render["denoise"].get<bool>() ? "1" : "0"},
        {"lucent.stages", render["stages"].dump()},
        {"lucent.render", render.dump()},
    };
    if (render.contains("rendered_camera"))
        out.push_back({"lucent.camera", render["rendered_camera"].dump()});
    return out;
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
    cmd->add_option("--camera", args.camera,
                    "The scene file's camera N (glTF's cameras, from 0); default: its first")
        ->type_name("N")
        ->check(CLI::Range(0, 1 << 30).description(""));
    add_camera_flags(cmd, args.camera_flags);
    cmd->add_option("--aov", args.aov,
                    "Also write these G-buffer layers into the .exr output beside RGBA: any of "
                    "albedo, normal, depth, position, instance (comma-separated)")
        ->type_name("LIST")
        ->each([&args](const std::string&) { args.aov_given = true; });
    cmd->add_flag("--denoise", args.denoise,
                  "Filter the image with the edge-avoiding à-trous denoiser (Dammertz et al. "
                  "2010) guided by the albedo, normal and position of the G-buffer");
    cmd->add_option("--denoise-passes", args.denoise_passes,
                    "Passes of the denoiser, the taps of pass i 2^i pixels apart; 0 = its "
                    "default (3; the paper has 5)")
        ->type_name("N")
        ->check(CLI::Range(0u, 10u).description(""))
        ->capture_default_str();
    cmd->add_flag("-q,--quiet", args.quiet, "Print nothing but errors");
    cmd->add_flag("--json", args.json,
                  "Print the settings and stage timings as one JSON object (no progress)");
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
                "  lucent render --sample pathtracer --scene cornell-materials --spp 256\n"
                "  lucent render --sample igi --eye 278,273,-500 --fov 50   # another view\n"
                "  lucent render --sample pathtracer --scene model.glb --camera 1\n"
                "  lucent render --json --out x.exr     # timings for scripts\n"
                "  lucent render --sample pathtracer --spp 4 --denoise --out denoised.exr\n"
                "  lucent render --sample pathtracer --aov albedo,normal,depth --out gbuffer.exr\n"
                "\nThe camera flags replace the parts of the scene's camera they give; the\n"
                "scene's own camera (--camera N of a glTF file's, or one framing the scene)\n"
                "gives the rest.\n");
    return cmd;
}

int run_render(const RenderArgs& args) {
    samples::RenderSettings settings = settings_from(args);
    // Under mpirun: every rank renders its pieces of each launch; rank 0 writes and prints.
    settings.ranks = join_ranks();
    const bool writes = !settings.ranks || settings.ranks->rank() == 0;
    check_image_path("--out", args.out);
    std::string extension = std::filesystem::path(args.out).extension().string();
    for (char& c : extension) c = char(std::tolower((unsigned char)c));
    const bool exr = extension == ".exr";
    if (settings.aovs.any() && !exr)
        throw UsageError("--aov " + quoted(args.aov) + ": AOV layers are channels of an OpenEXR "
                         "file, and --out " + quoted(args.out) + " is not one; use --out "
                         "NAME.exr");
    const samples::Sample& sample = samples::find_sample(args.sample);
    sample.read_options(settings);  // every --set checked before the render
    samples::check_aov_support(sample, settings);
    // An .exr gets alpha (coverage) from every sample with a G-buffer pass.
    settings.alpha = exr && sample.writes_aovs();
    const bool talk = !args.quiet && !args.json;
    if (talk) {
        // Before the render, which may take long: what is being rendered.
        std::printf("%s: %ux%u, backend %s, scene %s\n", sample.name.c_str(), settings.width,
                    settings.height, args.backend.c_str(),
                    settings.scene.empty() ? "(the sample's own)" : settings.scene.c_str());
        if (args.verbose) {
            std::printf("  threads %u, spp %u, repeat %u\n", settings.threads, settings.spp,
                        settings.repeat);
            for (const auto& [name, value] : settings.sets)
                std::printf("  --set %s=%s\n", name.c_str(), value.c_str());
        }
        std::fflush(stdout);
    }

    RenderProgress progress(talk);
    samples::RenderSettings run = settings;
    run.progress = [&progress](unsigned done, unsigned total) { progress.launches(done, total); };
    if (progress.shown()) {
        run.on_launch_progress = [&progress](const LaunchProgress& p) { progress.rows(p); };
        run.on_load_progress = [&progress](const std::string& stage, uint64_t done,
                                           uint64_t total) { progress.load(stage, done, total); };
    }
    const Clock::time_point start = Clock::now();
    samples::RenderResult result;
    run_agreed(settings.ranks, [&] { result = sample.render(run); });
    progress.finish();
    const Clock::time_point written = Clock::now();
    scene::ExrExtras extras;
    if (exr) {
        extras.attributes =
            exr_metadata(render_json(args, settings, sample, result, 0, ms_since(start)));
        // The layers move into the file; their names stay for --json.
        extras.channels = std::move(result.aovs);
        result.aovs.clear();
        for (const scene::ExrChannel& c : extras.channels) result.aovs.push_back({c.name, {}});
    }
    // Every rank learns whether rank 0's write failed, and all exit alike.
    run_agreed(settings.ranks, [&] {
        if (writes) scene::write_image(args.out, result.image, extras);
    });
    const double write_ms = ms_since(written);
    const double total_ms = ms_since(start);

    if (args.json) {
        std::printf("%s\n", render_json(args, settings, sample, result, write_ms, total_ms).dump(2).c_str());
        return 0;
    }
    if (args.quiet) return 0;
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

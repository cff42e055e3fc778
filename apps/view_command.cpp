// `lucent view`: checks the input like `render` does, then hands over to the viewer, which
// this build has only when GLFW, Dear ImGui and OpenGL were found at configure time.
#include "view_command.h"

#include <thread>

#include "camera_flags.h"
#include "cli_parse.h"
#include "lucent/error.h"
#include "samples/sample.h"
#include "scene/image_io.h"
#ifdef LUCENT_HAVE_VIEWER
#include "viewer/viewer.h"
#endif

namespace lucent::cli {
namespace {

samples::ViewDenoiser parse_view_denoiser(const std::string& flag, const std::string& text) {
    for (auto d : {samples::ViewDenoiser::kOff, samples::ViewDenoiser::kAtrous,
                   samples::ViewDenoiser::kSvgf})
        if (text == samples::view_denoiser_name(d)) return d;
    throw UsageError(flag + " " + quoted(text) + ": expected off, a-trous or svgf");
}

}  // namespace

CLI::App* add_view_command(CLI::App& app, ViewArgs& args) {
#ifdef LUCENT_HAVE_VIEWER
    const char* description = "Show a sample in a window, rendered as the camera moves";
#else
    const char* description =
        "Show a sample in a window (not in this build: it needs libglfw3-dev libimgui-dev "
        "libgl-dev at configure time)";
#endif
    CLI::App* cmd = app.add_subcommand("view", description);
    cmd->add_option("--sample", args.sample, "Sample to show (see `lucent render --help`)")
        ->type_name("NAME")
        ->capture_default_str();
    cmd->add_option("--size", args.size, "Rendered image size, each side 1..16384")
        ->type_name("WxH")
        ->capture_default_str();
    cmd->add_option("--backend", args.backend, "auto, cpu or cuda")
        ->type_name("KIND")
        ->capture_default_str();
    add_devices_option(cmd, args.devices);
    cmd->add_option("--scene", args.scene,
                    "Built-in scene or scene file (default: the sample's own)")
        ->type_name("NAME|FILE");
    cmd->add_option("--camera", args.camera,
                    "Start from the scene file's camera N (glTF's cameras, from 0)")
        ->type_name("N")
        ->check(CLI::Range(0, 1 << 30).description(""));
    add_camera_flags(cmd, args.camera_flags);
    cmd->add_option("--set", args.sets, "Sample option (repeatable)")->type_name("NAME=VALUE");
    cmd->add_option("--threads", args.threads,
                    "CPU worker threads, 0 = one per core but one (left to the window)")
        ->type_name("N")
        ->check(CLI::Range(0u, 4096u).description(""))
        ->capture_default_str();
    cmd->add_option("--spp", args.spp,
                    "Progressive samples (the path tracer) stop refining at this many samples "
                    "per pixel; 0 = never")
        ->type_name("N")
        ->check(CLI::Range(0u, 1000000u).description(""))
        ->capture_default_str();
    cmd->add_option("--frames", args.frames,
                    "Render this many frames, then exit (with --screenshot: a headless check)")
        ->type_name("N")
        ->check(CLI::Range(1u, 1000000u).description(""));
    std::string formats;  // the writers' list, as the error names it
    for (const scene::ImageFormat& f : scene::image_formats())
        formats += std::string(formats.empty() ? "" : " ") + f.extension;
    cmd->add_option("--screenshot", args.screenshot,
                    "With --frames: save what the window shows before exiting: " + formats +
                        " (the 8-bit window pixels; the float files hold them linear)")
        ->type_name("FILE");
    cmd->add_flag("--fit-window", args.fit_window,
                  "Render at the window's size, following it as it is resized (--size is the "
                  "first window's)");
    cmd->add_option("--soak", args.soak,
                    "Soak test: resize the window through 1x1 to 1280x720 and move the camera, "
                    "the panel, the denoiser and the options for this long (whole cycles), "
                    "rendering at the window's size; exit 1 when a frame the window shows is "
                    "not the rendered one or resident memory grew after the warm-up")
        ->type_name("SECONDS")
        ->check(CLI::Range(1.0, 604800.0).description(""));
    cmd->add_flag("--no-panel", args.no_panel, "Hide the control panel (Tab or H toggles it)");
    cmd->add_option("--ui-scale", args.ui_scale,
                    "Scale of the panel's text and controls; 0 = the window's content scale "
                    "(the desktop's)")
        ->type_name("S")
        ->check(CLI::Range(0.0f, 8.0f).description(""))
        ->capture_default_str();
    cmd->add_option("--denoiser", args.denoiser,
                    "Start with this denoiser: off, a-trous (the progressive image) or svgf "
                    "(temporal, for a moving camera); N cycles them. The path tracer has them")
        ->type_name("NAME")
        ->capture_default_str();
    cmd->add_flag("-v,--verbose", args.verbose,
                  "Print the backend, UI and render frames/s, the panel's size and the camera "
                  "as flags at exit");
    cmd->footer(
        "Mouse: left-drag orbit, right- or middle-drag pan, wheel zoom. F1 in the window lists\n"
        "every key and mouse binding; F copies the camera as --eye --look --up --fov.\n"
        "\nExamples:\n"
        "  lucent view --sample pathtracer --scene cornell-materials\n"
        "  lucent view --sample pathtracer --denoiser svgf          # denoised while it moves\n"
        "  lucent view --sample whitted --backend cpu --size 640x480\n"
        "  lucent view --sample fog --set step=0.1\n"
        "  lucent view --sample radiosity --set show_vpls=1     # then M, I and L toggle\n"
        "  xvfb-run -a -s '-screen 0 1280x1024x24' lucent view --sample whitted "
        "--size 160x120 --frames 2 --no-panel --screenshot view.png\n"
        "  xvfb-run -a -s '-screen 0 1280x1024x24' lucent view --sample whitted --backend cpu "
        "--size 160x120 --soak 600\n");
    return cmd;
}

int run_view(const ViewArgs& args) {
    samples::RenderSettings settings;
    const Size size = parse_size("--size", args.size);
    settings.width = size.width;
    settings.height = size.height;
    settings.backend = parse_backend("--backend", args.backend);
    settings.devices = parse_devices("--devices", args.devices);
    // The CPU backend leaves one core to the window by default, so the panel stays fluid
    // while a frame renders; --threads N overrides.
    settings.threads = args.threads;
    if (settings.threads == 0) {
        const unsigned cores = std::thread::hardware_concurrency();  // 0: unknown
        settings.threads = cores > 1 ? cores - 1 : 1;
    }
    settings.scene = args.scene;
    if (args.camera >= 0) settings.scene_camera = unsigned(args.camera);
    settings.camera = parse_camera_flags(args.camera_flags);
    settings.spp = args.spp;
    for (const std::string& text : args.sets) {
        auto [name, value] = parse_set("--set", text);
        settings.sets[name] = value;
    }
    if (!args.screenshot.empty()) {
        if (args.frames == 0)
            throw UsageError("--screenshot " + quoted(args.screenshot) +
                             ": needs --frames N (the frame to save)");
        check_image_path("--screenshot", args.screenshot);
    }
    if (args.soak > 0 && args.frames > 0)
        throw UsageError("--soak and --frames both end the run: give one of them");
    const samples::ViewDenoiser denoiser = parse_view_denoiser("--denoiser", args.denoiser);
    const samples::Sample& sample = samples::find_sample(args.sample);
    sample.read_options(settings);  // every --set checked before the window opens
#ifdef LUCENT_HAVE_VIEWER
    viewer::ViewerConfig config;
    config.sample = &sample;
    config.settings = settings;
    config.frames = args.frames;
    config.screenshot = args.screenshot;
    config.panel = !args.no_panel;
    config.ui_scale = args.ui_scale;
    config.denoiser = denoiser;
    config.verbose = args.verbose;
    config.fit_window = args.fit_window;
    config.soak = args.soak;
    return viewer::run_viewer(config);
#else
    throw Error(
        "this build has no viewer: GLFW, Dear ImGui or OpenGL was missing at configure time; "
        "install libglfw3-dev libimgui-dev libgl-dev (scripts/install-deps.sh does), then "
        "configure and build again");
#endif
}

}  // namespace lucent::cli

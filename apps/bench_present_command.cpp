// `lucent bench present`: turns flags into PresentBenchOptions; the measuring is in
// bench/present (built with OpenGL and EGL).
#include "bench_present_command.h"

#include "cli_parse.h"
#include "lucent/error.h"
#include "progress_bar.h"
#include "samples/sample.h"
#ifdef LUCENT_HAVE_PRESENT
#include "bench/present/present_bench.h"
#endif

namespace lucent::cli {

CLI::App* add_bench_present_command(CLI::App* bench, BenchPresentArgs& args) {
    CLI::App* c = bench->add_subcommand(
        "present",
        "The viewer's presentation path per frame (CUDA-OpenGL interop and host upload), in a "
        "headless OpenGL context");
    c->add_option("--sample", args.sample, "The sample that renders the frames")
        ->type_name("NAME")
        ->capture_default_str();
    c->add_option("--backend", args.backend, "cpu, cuda or auto")
        ->type_name("KIND")
        ->capture_default_str();
    c->add_option("--threads", args.threads, "CPU worker threads, 0 = one per core")
        ->type_name("N")
        ->check(CLI::Range(0u, 4096u).description(""));
    c->add_option("--size", args.size, "Frame size")->type_name("WxH")->capture_default_str();
    c->add_option("--frames", args.frames, "Frames timed per path (after 3 warm-up frames)")
        ->type_name("N")
        ->check(CLI::Range(1u, 100000u).description(""))
        ->capture_default_str();
    c->add_flag("--json", args.json, "One JSON object instead of the table");
    c->footer(
        "Examples:\n"
        "  lucent bench present --backend cuda                 # 1080p, interop vs host upload\n"
        "  lucent bench present --backend cpu --size 320x240 --frames 10 --json\n"
        "Needs EGL (a GPU driver's, or Mesa's software device); no window or X server.\n");
    return c;
}

int run_bench_present_command(const BenchPresentArgs& args) {
#ifdef LUCENT_HAVE_PRESENT
    bench::PresentBenchOptions options;
    options.sample = samples::find_sample(args.sample).name;
    options.backend = parse_backend("--backend", args.backend);
    options.threads = args.threads;
    const Size size = parse_size("--size", args.size);
    options.width = size.width;
    options.height = size.height;
    options.frames = args.frames;
    options.json = args.json;
    return run_with_progress_bar("bench present", "frames", options, bench::run_present_bench);
#else
    (void)args;
    throw Error(
        "lucent bench present: this build has no OpenGL/EGL (install libopengl-dev libegl-dev "
        "and build again)");
#endif
}

}  // namespace lucent::cli

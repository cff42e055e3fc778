// `lucent bench igi`: turns flags into IgiBenchOptions; the measuring is in bench/igi.
#include "bench_igi_command.h"

#include "bench/igi/igi_bench.h"
#include "cli_parse.h"
#include "cli_ranks.h"
#include "progress_bar.h"

namespace lucent::cli {

CLI::App* add_bench_igi_command(CLI::App* bench, BenchIgiArgs& args) {
    CLI::App* c = bench->add_subcommand(
        "igi",
        "Instant Global Illumination: canonical, then +imperfect visibility, "
        "+downsampling, +interleaving, x VPL counts (Marques and Santos, Fig. 4 and 5)");
    c->add_option("--scene", args.scene, "Built-in scene name or a .obj/.json/.ply file")
        ->type_name("NAME|FILE")
        ->capture_default_str();
    c->add_option("--backend", args.backend, "cpu, cuda or auto")
        ->type_name("KIND")
        ->capture_default_str();
    add_devices_option(c, args.devices);
    c->add_option("--threads", args.threads, "CPU worker threads, 0 = one per core")
        ->type_name("N")
        ->check(CLI::Range(0u, 4096u).description(""));
    c->add_option("--size", args.size, "Image size")->type_name("WxH")->capture_default_str();
    c->add_option("--frames", args.frames, "Frames timed per configuration, after one warm-up")
        ->type_name("N")
        ->check(CLI::Range(1u, 100000u).description(""))
        ->capture_default_str();
    c->add_option("--vpls", args.vpls, "VPL counts, comma-separated, each 1..65536")
        ->type_name("N,N,...")
        ->delimiter(',')
        ->check(CLI::Range(1u, 65536u).description(""));
    c->add_option("--downsample", args.downsample, "Downsampling window of '+downsampling', 2..16")
        ->type_name("N")
        ->check(CLI::Range(2u, 16u).description(""))
        ->capture_default_str();
    c->add_option("--interleave", args.interleave, "Interleaving window of '+interleaving', 2..8")
        ->type_name("M")
        ->check(CLI::Range(2u, 8u).description(""))
        ->capture_default_str();
    c->add_option("--reflection-layer", args.reflection_layer,
                  "1: the first reflected hits' indirect light is a G-buffer layer, accelerated "
                  "like the primary hits'; 0: inline, as in the paper")
        ->type_name("0|1")
        ->check(CLI::Range(0u, 1u).description(""))
        ->capture_default_str();
    c->add_flag("--json", args.json, "One JSON object instead of the table");
    c->footer(
        "Examples:\n"
        "  lucent bench igi                                  # cornell, 800x600, on the CPU\n"
        "  lucent bench igi --backend cuda --frames 100\n"
        "  LUCENT_SCENE_PATH=../shared/scenes lucent bench igi --scene "
        "bench/scenes/sponza-igi.json --backend cuda --json\n");
    return c;
}

int run_bench_igi_command(const BenchIgiArgs& args) {
    bench::IgiBenchOptions options;
    options.scene = args.scene;
    options.backend = parse_backend("--backend", args.backend);
    options.devices = parse_devices("--devices", args.devices);
    options.threads = args.threads;
    const Size size = parse_size("--size", args.size);
    options.width = size.width;
    options.height = size.height;
    options.frames = args.frames;
    options.vpls = args.vpls;
    options.downsample = args.downsample;
    options.interleave = args.interleave;
    options.reflection_layer = args.reflection_layer != 0;
    options.json = args.json;
    // Under mpirun: every frame's launches spread over the ranks; rank 0 prints the table.
    options.ranks = join_ranks();
    int code = 0;
    run_agreed(options.ranks, [&] {
        code = run_with_progress_bar("bench igi", "configurations", options, bench::run_igi_bench);
    });
    return code;
}

}  // namespace lucent::cli

// `lucent bench fog`: turns flags into FogBenchOptions; the measuring is in bench/fog.
#include "bench_fog_command.h"

#include "bench/fog/fog_bench.h"
#include "cli_parse.h"
#include "progress_bar.h"

namespace lucent::cli {

CLI::App* add_bench_fog_command(CLI::App* bench, BenchFogArgs& args) {
    CLI::App* c = bench->add_subcommand(
        "fog",
        "Volumetric fog: no fog, then steps 0.1, 0.05, 0.01, frames/s over a moving "
        "camera (Sebald, Table 1)");
    c->add_option("--backend", args.backend, "cpu, cuda or auto")
        ->type_name("KIND")
        ->capture_default_str();
    add_devices_option(c, args.devices);
    c->add_option("--threads", args.threads, "CPU worker threads, 0 = one per core")
        ->type_name("N")
        ->check(CLI::Range(0u, 4096u).description(""));
    c->add_option("--size", args.size, "Image size")->type_name("WxH")->capture_default_str();
    c->add_option("--frames", args.frames, "Frames per configuration, once around the orbit")
        ->type_name("N")
        ->check(CLI::Range(1u, 100000u).description(""))
        ->capture_default_str();
    c->add_flag("--json", args.json, "One JSON object instead of the table");
    c->footer(
        "Examples:\n"
        "  lucent bench fog --size 320x240 --frames 8     # a quick look on the CPU\n"
        "  lucent bench fog --backend cuda --frames 300\n");
    return c;
}

int run_bench_fog_command(const BenchFogArgs& args) {
    bench::FogBenchOptions options;
    options.backend = parse_backend("--backend", args.backend);
    options.devices = parse_devices("--devices", args.devices);
    options.threads = args.threads;
    const Size size = parse_size("--size", args.size);
    options.width = size.width;
    options.height = size.height;
    options.frames = args.frames;
    options.json = args.json;
    return run_with_progress_bar("bench fog", "frames", options, bench::run_fog_bench);
}

}  // namespace lucent::cli

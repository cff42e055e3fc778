// `lucent bench spheres`: turns flags into SpheresBenchOptions; the measuring is in
// bench/spheres.
#include "bench_spheres_command.h"

#include "bench/spheres/spheres_bench.h"
#include "cli_parse.h"

namespace lucent::cli {

CLI::App* add_bench_spheres_command(CLI::App* bench, BenchSpheresArgs& args) {
    CLI::App* c = bench->add_subcommand(
        "spheres",
        "Primary rays into a field of spheres: built-in spheres against the same spheres as a "
        "custom intersection program, in one run");
    c->add_option("--backend", args.backend, "cpu, cuda or auto")
        ->type_name("KIND")
        ->capture_default_str();
    c->add_option("--threads", args.threads, "CPU worker threads, 0 = one per core")
        ->type_name("N")
        ->check(CLI::Range(0u, 4096u).description(""));
    c->add_option("--count", args.count, "Spheres, 1..16777216")
        ->type_name("N")
        ->check(CLI::Range(1u, 16777216u).description(""))
        ->capture_default_str();
    c->add_option("--size", args.size,
                  "Image size (default 1024x768; 3840x2160 with --backend cuda)")
        ->type_name("WxH");
    c->add_option("--repeat", args.repeat, "Timed launches of each (median reported)")
        ->type_name("N")
        ->check(CLI::Range(1, 1000).description(""))
        ->capture_default_str();
    c->add_flag("--json", args.json, "One JSON object instead of the table");
    c->footer(
        "Examples:\n"
        "  lucent bench spheres --count 100000 --size 640x480   # a quick look on the CPU\n"
        "  lucent bench spheres --backend cuda                   # 1M spheres at 3840x2160\n");
    return c;
}

int run_bench_spheres_command(const BenchSpheresArgs& args) {
    bench::SpheresBenchOptions options;
    options.backend = parse_backend("--backend", args.backend);
    options.threads = args.threads;
    options.count = args.count;
    const Size size = parse_size(
        "--size", !args.size.empty() ? args.size
                                     : (options.backend == BackendKind::kCuda ? "3840x2160"
                                                                              : "1024x768"));
    options.width = size.width;
    options.height = size.height;
    options.repeat = args.repeat;
    options.json = args.json;
    return bench::run_spheres_bench(options);
}

}  // namespace lucent::cli

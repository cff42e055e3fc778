// `lucent bench curves`: turns flags into CurvesBenchOptions; the measuring is in
// bench/curves.
#include "bench_curves_command.h"

#include <map>

#include "bench/curves/curves_bench.h"
#include "cli_parse.h"

namespace lucent::cli {

namespace {

const std::map<std::string, CurveType> kCurveTypes = {{"linear", kCurveLinear},
                                                      {"quadratic", kCurveQuadraticBSpline},
                                                      {"cubic", kCurveCubicBSpline},
                                                      {"catmull-rom", kCurveCatmullRom}};

}  // namespace

CLI::App* add_bench_curves_command(CLI::App* bench, BenchCurvesArgs& args) {
    CLI::App* c = bench->add_subcommand(
        "curves",
        "Primary and diffuse rays into a procedural head of hair made of built-in curves");
    c->add_option("--backend", args.backend, "cpu, cuda or auto")
        ->type_name("KIND")
        ->capture_default_str();
    c->add_option("--threads", args.threads, "CPU worker threads, 0 = one per core")
        ->type_name("N")
        ->check(CLI::Range(0u, 4096u).description(""));
    c->add_option("--segments", args.segments, "Curve segments, 1..16777216")
        ->type_name("N")
        ->check(CLI::Range(1u, 16777216u).description(""))
        ->capture_default_str();
    c->add_option("--type", args.type, "linear, quadratic, cubic (B-splines) or catmull-rom")
        ->type_name("TYPE")
        ->check(CLI::IsMember({"linear", "quadratic", "cubic", "catmull-rom"}))
        ->capture_default_str();
    c->add_option("--size", args.size,
                  "Image size (default 640x480; 3840x2160 with --backend cuda)")
        ->type_name("WxH");
    c->add_option("--repeat", args.repeat, "Timed launches of each ray set (median reported)")
        ->type_name("N")
        ->check(CLI::Range(1, 1000).description(""))
        ->capture_default_str();
    c->add_flag("--json", args.json, "One JSON object instead of the table");
    c->footer(
        "Examples:\n"
        "  lucent bench curves --segments 20000            # a quick look on the CPU\n"
        "  lucent bench curves --backend cuda              # 100K cubic segments at 3840x2160\n");
    return c;
}

int run_bench_curves_command(const BenchCurvesArgs& args) {
    bench::CurvesBenchOptions options;
    options.backend = parse_backend("--backend", args.backend);
    options.threads = args.threads;
    options.segments = args.segments;
    options.type = kCurveTypes.at(args.type);
    const Size size = parse_size(
        "--size", !args.size.empty() ? args.size
                                     : (options.backend == BackendKind::kCuda ? "3840x2160"
                                                                              : "640x480"));
    options.width = size.width;
    options.height = size.height;
    options.repeat = args.repeat;
    options.json = args.json;
    return bench::run_curves_bench(options);
}

}  // namespace lucent::cli

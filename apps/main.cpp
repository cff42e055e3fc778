// The `lucent` command line: render or view a sample, or run the benchmarks.
// Exit codes: 0 success, 1 runtime error (engine, files), 2 bad command-line input.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "bench_command.h"
#include "bench_fog_command.h"
#include "bench_igi_command.h"
#include "bench_present_command.h"
#include "bench_curves_command.h"
#include "bench_spheres_command.h"
#include "cli_errors.h"
#include "cli_parse.h"
#include "cli_ranks.h"
#include "compare_command.h"
#include "lucent/error.h"
#include "lucent/version.h"
#include "noise_command.h"
#include "render_command.h"
#include "samples/settings_error.h"
#include "scene/temp_file_cleanup.h"
#include "tea_command.h"
#include "view_command.h"

namespace {

constexpr int kRuntimeExit = 1;
constexpr int kUsageExit = 2;

int report(const std::string& where, const char* kind, const char* what, int code,
           bool every_rank_alike = false) {
    std::fflush(stdout);
    // Under mpirun, what every rank meets alike (a usage error, an agreed rank failure) is
    // printed once, by rank 0.
    if (every_rank_alike && lucent::cli::launcher_rank() != 0) return code;
    std::fprintf(stderr, "%s: %s%s\n", where.c_str(), kind, what);
    return code;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace lucent::cli;
    // A render killed while it writes its image leaves no temporary file behind.
    lucent::scene::remove_temp_files_on_signals();
    CLI::App app{"Lucent: an open, programmable ray-tracing engine", "lucent"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("lucent ") + lucent::version() +
#if LUCENT_HAVE_CUDA
                                          " (backends: cpu, cuda)"
#else
                                          " (backends: cpu)"
#endif
    );
    app.footer(
        "Examples:\n"
        "  lucent render --sample whitted --size 1024x1024 --out whitted.png\n"
        "  lucent view --sample pathtracer --scene cornell-materials\n"
        "  lucent bench rays --scene ../shared/scenes/sponza.obj\n"
        "  lucent tea --block 0,0 --key 0,0,0,0 --rounds 32\n"
        "  lucent compare reference.exr render.exr --error-image flip.png\n"
        "Run `lucent render --help` for the samples and their options.\n");

    RenderArgs render_args;
    ViewArgs view_args;
    BenchRaysArgs rays_args;
    BenchBuildArgs build_args;
    BenchTeaArgs bench_tea_args;
    BenchIgiArgs bench_igi_args;
    BenchFogArgs bench_fog_args;
    BenchPresentArgs bench_present_args;
    BenchSpheresArgs bench_spheres_args;
    BenchCurvesArgs bench_curves_args;
    TeaArgs tea_args;
    NoiseArgs noise_args;
    CompareArgs compare_args;
    std::string where = "lucent";
    try {
        CLI::App* render = add_render_command(app, render_args);
        CLI::App* view = add_view_command(app, view_args);
        BenchCommands bench = add_bench_commands(app, rays_args, build_args, bench_tea_args);
        CLI::App* bench_igi = add_bench_igi_command(bench.bench, bench_igi_args);
        CLI::App* bench_fog = add_bench_fog_command(bench.bench, bench_fog_args);
        CLI::App* bench_present = add_bench_present_command(bench.bench, bench_present_args);
        CLI::App* bench_spheres = add_bench_spheres_command(bench.bench, bench_spheres_args);
        CLI::App* bench_curves = add_bench_curves_command(bench.bench, bench_curves_args);
        CLI::App* tea = add_tea_command(app, tea_args);
        CLI::App* noise = add_noise_command(app, noise_args);
        CLI::App* compare = add_compare_command(app, compare_args);
        try {
            app.parse(argc, argv);
        } catch (const CLI::ParseError& e) {
            // --help and --version print and exit 0; every other parse error is a usage
            // error, worded as Lucent's own.
            if (e.get_exit_code() == 0) return app.exit(e);
            const UsageMessage message = usage_message(app, e, argc, argv);
            return report(message.where, "", message.text.c_str(), kUsageExit, true);
        }
        if (render->parsed()) {
            where = "lucent render";
            return run_render(render_args);
        }
        if (view->parsed()) {
            where = "lucent view";
            return run_view(view_args);
        }
        if (bench.rays->parsed()) {
            where = "lucent bench rays";
            return run_bench_rays_command(rays_args);
        }
        if (bench.build->parsed()) {
            where = "lucent bench build";
            return run_bench_build_command(build_args);
        }
        if (bench.tea->parsed()) {
            where = "lucent bench tea";
            return run_bench_tea_command(bench_tea_args);
        }
        if (bench_fog->parsed()) {
            where = "lucent bench fog";
            return run_bench_fog_command(bench_fog_args);
        }
        if (bench_present->parsed()) {
            where = "lucent bench present";
            return run_bench_present_command(bench_present_args);
        }
        if (bench_spheres->parsed()) {
            where = "lucent bench spheres";
            return run_bench_spheres_command(bench_spheres_args);
        }
        if (bench_curves->parsed()) {
            where = "lucent bench curves";
            return run_bench_curves_command(bench_curves_args);
        }
        if (bench_igi->parsed()) {
            where = "lucent bench igi";
            return run_bench_igi_command(bench_igi_args);
        }
        if (tea->parsed()) {
            where = "lucent tea";
            return run_tea(tea_args);
        }
        if (compare->parsed()) {
            where = "lucent compare";
            return run_compare(compare_args);
        }
        if (noise->parsed()) {
            where = "lucent noise";
            return run_noise(noise_args);
        }
        return report(where, "", "no command given; run `lucent --help`", kUsageExit);
    } catch (const UsageError& e) {
        return report(where, "", e.what(), kUsageExit, true);
    } catch (const lucent::samples::SettingsError& e) {
        return report(where, "", e.what(), kUsageExit, true);
    } catch (const lucent::RankError& e) {
        return report(where, "error: ", e.what(), kRuntimeExit, true);
    } catch (const lucent::Error& e) {
        return report(where, "error: ", e.what(), kRuntimeExit);
    } catch (const std::exception& e) {
        return report(where, "unexpected error: ", e.what(), kRuntimeExit);
    }
}

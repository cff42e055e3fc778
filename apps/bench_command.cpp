// `lucent bench ...`: turns flags into bench options; the measuring is in bench/.
#include "bench_command.h"

#include <filesystem>

#include "bench/build/build_bench.h"
#include "bench/rays/rays_bench.h"
#include "bench/tea/tea_bench.h"
#include "cli_parse.h"
#include "lucent/context.h"
#include "lucent/error.h"
#include "progress_bar.h"

namespace lucent::cli {
namespace {

/// A missing scene is a runtime error (exit 1) like an unreadable one, caught before timing.
/// Checked here rather than by CLI11's required(): CLI11 reports a missing required flag
/// before an unknown one, so `bench rays --sceen x.obj` would not name the typo.
void require_scene(const std::string& path) {
    if (path.empty())
        throw UsageError(
            "--scene is required: give an .obj file, e.g. ../shared/scenes/sponza.obj");
}

void check_scene_file(const std::string& path) {
    require_scene(path);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw Error("--scene " + path + ": no such file (give an .obj file, e.g. " +
                    "../shared/scenes/sponza.obj)");
}

/// The backend a benchmark measures: "cuda" for --backend cuda, else the CPU ("auto" too,
/// so the default figures stay comparable). bench/ says why when CUDA cannot run.
std::string bench_backend(const std::string& text) {
    return parse_backend("--backend", text) == BackendKind::kCuda ? "cuda" : "cpu";
}

}  // namespace

BenchCommands add_bench_commands(CLI::App& app, BenchRaysArgs& rays, BenchBuildArgs& build,
                                 BenchTeaArgs& tea) {
    BenchCommands cmds;
    cmds.bench = app.add_subcommand("bench", "Benchmarks: ray throughput and BVH build time");
    cmds.bench->require_subcommand(1);
    cmds.bench->footer(
        "Examples:\n"
        "  lucent bench rays --scene ../shared/scenes/sponza.obj\n"
        "  lucent bench build --scene ../shared/scenes/sponza.obj --json\n");

    CLI::App* r = cmds.bench->add_subcommand(
        "rays", "Trace the primary, shadow and diffuse ray sets of shared/BENCH.md");
    r->add_option("--scene", rays.scene, "OBJ file (required)")->type_name("FILE");
    r->add_option("--eye", rays.eye, "Camera position x,y,z")->type_name("X,Y,Z");
    r->add_option("--look", rays.look, "Point looked at x,y,z")->type_name("X,Y,Z");
    r->add_option("--up", rays.up, "Up vector x,y,z")->type_name("X,Y,Z");
    r->add_option("--fov", rays.fov, "Vertical field of view in degrees, (0, 180)")
        ->type_name("DEG");
    r->add_option("--light", rays.light, "Point light for shadow rays x,y,z")->type_name("X,Y,Z");
    r->add_option("--size", rays.size,
                  "Image size (default 1024x768; 3840x2160 with --backend cuda)")
        ->type_name("WxH");
    r->add_option("--repeat", rays.repeat, "Timed repeats (median reported)")
        ->type_name("N")
        ->check(CLI::Range(1, 1000).description(""))
        ->capture_default_str();
    r->add_option("--threads", rays.threads, "CPU worker threads, 0 = one per core")
        ->type_name("N")
        ->check(CLI::Range(0u, 4096u).description(""))
        ->capture_default_str();
    r->add_flag("--no-peer", rays.no_peer, "Do not run the peer engine (Embree)");
    r->add_flag("--programs", rays.programs,
                "Also trace the ray sets through a program module launched by a Context "
                "(bench/rays/rays_programs.h): the engine's per-ray path beside the kernels");
    r->add_option("--builder", rays.builder,
                  "The BVH: auto (the engine's default: built on the GPU with --backend cuda, "
                  "object splits only, and upgraded to the host's tree with spatial splits "
                  "before the first timed launch), gpu (auto without the upgrade: the GPU-built "
                  "tree) or sah (Builder::kBinnedSah: the host's binned SAH with spatial "
                  "splits, the traversal-first build). The CUDA kernels and --programs trace "
                  "it; the CPU backend builds sah either way")
        ->type_name("NAME")
        ->check(CLI::IsMember({"auto", "gpu", "sah"}))
        ->capture_default_str();
    r->add_flag("--json", rays.json, "Machine-readable output");
    r->add_option("--backend", rays.backend, "cpu, auto or cuda")
        ->type_name("KIND")
        ->capture_default_str();
    r->footer(
        "The camera flags --eye --look --up --fov --light go together; without them the\n"
        "viewpoint comes from cameras.txt beside the scene.\n"
        "\nExamples:\n"
        "  lucent bench rays --scene ../shared/scenes/sponza.obj\n"
        "  lucent bench rays --scene ../shared/scenes/bunny.obj --size 512x384 --repeat 9\n"
        "  lucent bench rays --scene my.obj --eye 0,1,5 --look 0,1,0 --up 0,1,0 --fov 45 "
        "--light 0,5,0\n");

    CLI::App* t = cmds.bench->add_subcommand(
        "tea", "TEA random numbers in 1 MB launches, fixed against generated key (Sebald Table 2)");
    t->add_option("--backend", tea.backend, "cpu, cuda or auto")
        ->type_name("KIND")
        ->capture_default_str();
    t->add_option("--threads", tea.threads, "CPU worker threads, 0 = one per core")
        ->type_name("N")
        ->check(CLI::Range(0u, 4096u).description(""))
        ->capture_default_str();
    t->add_option("--megabytes", tea.megabytes, "Output per key variant, 1..65536")
        ->type_name("MB")
        ->check(CLI::Range(1u, 65536u).description(""))
        ->capture_default_str();
    t->add_option("--rounds", tea.rounds, "TEA rounds, 1..64")
        ->type_name("N")
        ->check(CLI::Range(1u, 64u).description(""))
        ->capture_default_str();
    t->add_option("--device", tea.device, "Device identifier in the generated key")->type_name("D");
    t->add_option("--seed", tea.seed, "Seed in the generated key")->type_name("S");
    t->add_flag("--json", tea.json, "One JSON object instead of text");
    t->footer(
        "\nExamples:\n  lucent bench tea\n  lucent bench tea --megabytes 256 --rounds 4 --json\n");
    cmds.tea = t;

    CLI::App* b = cmds.bench->add_subcommand("build", "Time the BVH build of a scene");
    b->add_option("--scene", build.scene, "OBJ file (required)")->type_name("FILE");
    b->add_option("--repeat", build.repeat, "Timed repeats (median reported)")
        ->type_name("N")
        ->check(CLI::Range(1, 1000).description(""))
        ->capture_default_str();
    b->add_option("--threads", build.threads, "CPU worker threads, 0 = one per core")
        ->type_name("N")
        ->check(CLI::Range(0u, 4096u).description(""))
        ->capture_default_str();
    b->add_flag("--no-peer", build.no_peer, "Do not run the peer engine (Embree)");
    b->add_flag("--json", build.json, "Machine-readable output");
    b->add_option("--backend", build.backend,
                  "cpu, auto or cuda (cuda: the GPU builder, binned SAH or with "
                  "LUCENT_GPU_BUILDER=hploc H-PLOC, against the host SAH build, and the "
                  "Mrays/s of both trees)")
        ->type_name("KIND")
        ->capture_default_str();
    b->add_option("--subdivide", build.subdivide,
                  "Cut every triangle into 4 at its edge midpoints, N times (a bigger mesh "
                  "of the same shape: sponza with 2 has 1.06M triangles)")
        ->type_name("N")
        ->check(CLI::Range(0u, 5u).description(""))
        ->capture_default_str();
    b->add_option("--size", build.size,
                  "Image size of the ray sets both trees trace with --backend cuda (default "
                  "3840x2160; the viewpoint comes from cameras.txt beside the scene)")
        ->type_name("WxH");
    b->footer(
        "Examples:\n"
        "  lucent bench build --scene ../shared/scenes/sponza.obj\n"
        "  lucent bench build --scene ../shared/scenes/dragon.obj --repeat 9 --json\n"
        "  lucent bench build --backend cuda --scene ../shared/scenes/sponza.obj --subdivide 2\n");
    cmds.rays = r;
    cmds.build = b;
    return cmds;
}

int run_bench_rays_command(const BenchRaysArgs& args) {
    require_scene(args.scene);
    bench::RaysOptions options;
    options.scene = args.scene;
    options.backend = bench_backend(args.backend);
    const Size size = parse_size(
        "--size",
        !args.size.empty() ? args.size : (options.backend == "cuda" ? "3840x2160" : "1024x768"));
    options.width = size.width;
    options.height = size.height;
    options.repeat = args.repeat;
    options.threads = args.threads;
    options.peer = !args.no_peer;
    options.programs = args.programs;
    options.builder = args.builder == "sah" ? Builder::kBinnedSah : Builder::kAuto;
    options.tree_upgrades = args.builder == "gpu" ? TreeUpgrades::kOff : TreeUpgrades::kWithBuild;
    options.json = args.json;

    // A partial camera would silently mix given and default values: refuse it.
    const std::pair<const char*, const std::string*> camera[] = {{"--eye", &args.eye},
                                                                 {"--look", &args.look},
                                                                 {"--up", &args.up},
                                                                 {"--fov", &args.fov},
                                                                 {"--light", &args.light}};
    std::string given, missing;
    for (const auto& [flag, value] : camera)
        (value->empty() ? missing : given) += std::string(" ") + flag;
    if (!given.empty() && !missing.empty())
        throw UsageError("the camera flags go together: given" + given + ", missing" + missing +
                         " (or give none to use cameras.txt beside the scene)");
    if (!given.empty()) {
        options.has_camera = true;
        options.eye = parse_vec3("--eye", args.eye);
        options.look = parse_vec3("--look", args.look);
        options.up = parse_vec3("--up", args.up);
        options.fov = parse_float("--fov", args.fov, 0.f, 180.f, /*open=*/true);
        options.light = parse_vec3("--light", args.light);
    }
    check_scene_file(args.scene);
    return bench::run_bench_rays(options);
}

int run_bench_build_command(const BenchBuildArgs& args) {
    // Flags first (usage errors), then the file (a runtime error).
    const Size size = parse_size("--size", args.size.empty() ? "3840x2160" : args.size);
    check_scene_file(args.scene);
    bench::BuildBenchOptions options;
    options.scene = args.scene;
    options.repeat = args.repeat;
    options.threads = args.threads;
    options.peer = !args.no_peer;
    options.json = args.json;
    options.backend = bench_backend(args.backend);
    options.subdivide = args.subdivide;
    options.width = size.width;
    options.height = size.height;
    return bench::run_bench_build(options);
}

int run_bench_tea_command(const BenchTeaArgs& args) {
    bench::TeaBenchOptions options;
    options.backend = parse_backend("--backend", args.backend);
    options.threads = args.threads;
    options.megabytes = args.megabytes;
    options.rounds = args.rounds;
    options.device = args.device;
    options.seed = args.seed;
    options.json = args.json;
    return run_with_progress_bar("bench tea", "MB", options, bench::run_tea_bench);
}

}  // namespace lucent::cli

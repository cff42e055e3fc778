// `lucent bench rays`, `bench build` and `bench tea`: the command-line front of
// bench/rays/rays_bench.h, bench/build/build_bench.h and bench/tea/tea_bench.h.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace lucent::cli {

/// `bench rays` options as typed; parsed and checked by run_bench_rays_command.
struct BenchRaysArgs {
    std::string scene;
    std::string eye, look, up, fov, light;  // all or none
    std::string size;  // default 1024x768, or 3840x2160 with --backend cuda (BENCH.md)
    std::string backend = "cpu";
    int repeat = 5;
    unsigned threads = 0;
    bool no_peer = false;
    bool programs = false;  // --programs
    std::string builder = "auto";  // --builder: auto, gpu or sah
    bool json = false;
};

/// `bench build` options as typed.
struct BenchBuildArgs {
    std::string scene;
    int repeat = 5;
    unsigned threads = 0;
    bool no_peer = false;
    bool json = false;
    std::string backend = "cpu";
    unsigned subdivide = 0;  // each triangle cut into 4, this many times
    std::string size;        // rays of the --backend cuda comparison, WxH
};

/// `bench tea` options as typed.
struct BenchTeaArgs {
    std::string backend = "cpu";
    unsigned threads = 0;
    unsigned megabytes = 2048;
    unsigned rounds = 2;
    unsigned device = 0, seed = 0;
    bool json = false;
};

struct BenchCommands {
    CLI::App* bench = nullptr;
    CLI::App* rays = nullptr;
    CLI::App* build = nullptr;
    CLI::App* tea = nullptr;
};

/// Adds `bench` with its `rays` and `build` subcommands to `app`.
BenchCommands add_bench_commands(CLI::App& app, BenchRaysArgs& rays, BenchBuildArgs& build,
                                 BenchTeaArgs& tea);
/// Runs a parsed `bench tea`; returns the exit code.
int run_bench_tea_command(const BenchTeaArgs& args);
/// Runs a parsed `bench rays`; returns the exit code. Throws UsageError, lucent::Error.
int run_bench_rays_command(const BenchRaysArgs& args);
/// Runs a parsed `bench build`; returns the exit code.
int run_bench_build_command(const BenchBuildArgs& args);

}  // namespace lucent::cli

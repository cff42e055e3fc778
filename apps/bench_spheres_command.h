// `lucent bench spheres`: command-line front of bench/spheres/spheres_bench.h.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace lucent::cli {

struct BenchSpheresArgs {
    std::string backend = "cpu";
    unsigned threads = 0;
    unsigned count = 1000000;
    std::string size;  // default 1024x768, or 3840x2160 with --backend cuda
    int repeat = 5;
    bool json = false;
};

/// Adds `spheres` under the `bench` command.
CLI::App* add_bench_spheres_command(CLI::App* bench, BenchSpheresArgs& args);
/// Runs a parsed `bench spheres`; returns the exit code. Throws UsageError, lucent::Error.
int run_bench_spheres_command(const BenchSpheresArgs& args);

}  // namespace lucent::cli

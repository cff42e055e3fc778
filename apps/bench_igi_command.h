// `lucent bench igi`: command-line front of bench/igi/igi_bench.h.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace lucent::cli {

struct BenchIgiArgs {
    std::string scene = "cornell";
    std::string backend = "cpu";
    std::string devices;
    unsigned threads = 0;
    std::string size = "800x600";
    unsigned frames = 10;
    std::vector<unsigned> vpls{30, 90, 180};
    unsigned downsample = 4, interleave = 3;
    unsigned reflection_layer = 1;
    bool json = false;
};

/// Adds `igi` under the `bench` command.
CLI::App* add_bench_igi_command(CLI::App* bench, BenchIgiArgs& args);
/// Runs a parsed `bench igi`; returns the exit code. Throws UsageError, lucent::Error.
int run_bench_igi_command(const BenchIgiArgs& args);

}  // namespace lucent::cli

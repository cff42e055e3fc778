// `lucent bench fog`: command-line front of bench/fog/fog_bench.h.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace lucent::cli {

struct BenchFogArgs {
    std::string backend = "cpu";
    std::string devices;
    unsigned threads = 0;
    std::string size = "1024x768";
    unsigned frames = 30;
    bool json = false;
};

/// Adds `fog` under the `bench` command.
CLI::App* add_bench_fog_command(CLI::App* bench, BenchFogArgs& args);
/// Runs a parsed `bench fog`; returns the exit code. Throws UsageError, lucent::Error.
int run_bench_fog_command(const BenchFogArgs& args);

}  // namespace lucent::cli

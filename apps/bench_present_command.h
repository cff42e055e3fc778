// `lucent bench present`: command-line front of bench/present/present_bench.h.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace lucent::cli {

struct BenchPresentArgs {
    std::string sample = "whitted";
    std::string backend = "auto";
    unsigned threads = 0;
    std::string size = "1920x1080";
    unsigned frames = 100;
    bool json = false;
};

/// Adds `present` under the `bench` command.
CLI::App* add_bench_present_command(CLI::App* bench, BenchPresentArgs& args);
/// Runs a parsed `bench present`; returns the exit code. Throws UsageError, lucent::Error.
int run_bench_present_command(const BenchPresentArgs& args);

}  // namespace lucent::cli

// `lucent bench curves`: command-line front of bench/curves/curves_bench.h.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace lucent::cli {

struct BenchCurvesArgs {
    std::string backend = "cpu";
    unsigned threads = 0;
    unsigned segments = 100000;
    std::string type = "cubic";
    std::string size;  // default 640x480, or 3840x2160 with --backend cuda
    int repeat = 5;
    bool json = false;
};

/// Adds `curves` under the `bench` command.
CLI::App* add_bench_curves_command(CLI::App* bench, BenchCurvesArgs& args);
/// Runs a parsed `bench curves`; returns the exit code. Throws UsageError, lucent::Error.
int run_bench_curves_command(const BenchCurvesArgs& args);

}  // namespace lucent::cli

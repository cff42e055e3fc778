// `lucent noise`: TEA noise images of the fog sample (Sebald Figures 5-7).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace lucent::cli {

struct NoiseArgs {
    std::string kind = "white";  // white (64x64), gradient (256x256), spectrum (1024x1024)
    unsigned rounds = 4;
    unsigned size = 0;  // 0: the kind's size above
    std::string out = "noise.png";
    long long seed = -1;  // >= 0: a per-device key (Fig. 4) from (device, seed)
    unsigned device = 0;
};

/// Adds the `noise` subcommand to `app`; its options fill `args`.
CLI::App* add_noise_command(CLI::App& app, NoiseArgs& args);
/// Runs a parsed `noise`; returns the exit code.
int run_noise(const NoiseArgs& args);

}  // namespace lucent::cli

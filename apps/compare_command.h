// `lucent compare REFERENCE TEST`: RMSE, relative MSE, PSNR and FLIP between two images.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace lucent::cli {

struct CompareArgs {
    std::string reference, test;
    std::string error_image;  // --error-image: the FLIP map
    double pixels_per_degree = 0;  // 0: FLIP's default observer
    bool json = false;
    double fail_above = -1;  // --fail-above: exit 1 when mean FLIP is above it; <0: never
};

CLI::App* add_compare_command(CLI::App& app, CompareArgs& args);
/// Runs a parsed `compare`; returns the exit code. Throws lucent::Error for unreadable images.
int run_compare(const CompareArgs& args);

}  // namespace lucent::cli

// `lucent tea`: the TEA generator of the fog sample (Sebald §3.2) from the command line.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace lucent::cli {

struct TeaArgs {
    std::string block = "0,0";    // v0,v1
    std::string key = "0,0,0,0";  // k0,k1,k2,k3
    unsigned rounds = 32;
    bool statistics = false;     // the table of rounds against output statistics
    unsigned blocks = 1u << 20;  // blocks measured per row of that table
};

/// Adds the `tea` subcommand to `app`; its options fill `args`.
CLI::App* add_tea_command(CLI::App& app, TeaArgs& args);
/// Runs a parsed `tea`; returns the exit code. Throws UsageError for bad words.
int run_tea(const TeaArgs& args);

}  // namespace lucent::cli

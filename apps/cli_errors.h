// CLI11's parse errors in the style of Lucent's other usage errors: "lucent render: --spp:
// -3 is not in 0..1000000; run `lucent render --help`", with "did you mean" for a mistyped
// command, flag or sample.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace lucent::cli {

struct UsageMessage {
    std::string where;  // "lucent render": the command whose arguments were wrong
    std::string text;   // what was wrong and the fix
};

/// The message for a parse error that is not --help or --version (argv: the command line).
UsageMessage usage_message(CLI::App& app, const CLI::ParseError& error, int argc,
                           const char* const* argv);

}  // namespace lucent::cli

// Every subcommand's --help shows examples, every benchmark has --json, and unknown flags or
// bad values are refused with a message naming them (exit code 2).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <string>

#include "samples/nearest_name.h"

namespace {

struct CliRun {
    int exit_code = -1;
    std::string output;
};

CliRun run_lucent(const std::string& args) {
    CliRun r;
    FILE* pipe = popen((std::string("'") + LUCENT_CLI + "' " + args + " 2>&1").c_str(), "r");
    if (!pipe) return r;
    char buffer[4096];
    size_t n;
    while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) r.output.append(buffer, n);
    const int status = pclose(pipe);
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

const char* const kCommands[] = {"render",      "view",      "bench rays",    "bench build",
                                 "bench tea",   "bench igi", "bench fog",     "bench spheres",
                                 "bench curves", "tea",      "noise",         "compare"};

TEST(CliHelp, EverySubcommandShowsExamplesOfItself) {
    for (const char* command : kCommands) {
        const CliRun r = run_lucent(std::string(command) + " --help");
        EXPECT_EQ(r.exit_code, 0) << command;
        EXPECT_NE(r.output.find("Examples:"), std::string::npos) << command << "\n" << r.output;
        EXPECT_NE(r.output.find(std::string("lucent ") + command + " "), std::string::npos)
            << command << ": no example runs it\n"
            << r.output;
    }
}

TEST(CliHelp, EveryBenchmarkHasJsonOutput) {
    for (const char* bench : {"bench rays", "bench build", "bench tea", "bench igi", "bench fog",
                              "bench spheres", "bench curves"}) {
        const CliRun r = run_lucent(std::string(bench) + " --help");
        EXPECT_NE(r.output.find("--json"), std::string::npos) << bench << "\n" << r.output;
    }
}

TEST(CliHelp, TopLevelHelpListsView) {
    const CliRun r = run_lucent("--help");
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.output.find("view"), std::string::npos) << r.output;
}

TEST(CliHelp, UnknownFlagsAreNamedForEverySubcommand) {
    for (const char* command : kCommands) {
        const CliRun r = run_lucent(std::string(command) + " --frobnicate");
        EXPECT_EQ(r.exit_code, 2) << command << "\n" << r.output;
        EXPECT_NE(r.output.find("--frobnicate"), std::string::npos) << command << "\n" << r.output;
    }
}

TEST(CliHelp, OutOfRangeValuesNameTheFlagAndTheRange) {
    struct Case {
        const char* args;
        const char* flag;
        const char* range;
    };
    const Case cases[] = {
        {"render --threads 5000", "--threads", "4096"},
        {"render --repeat 0", "--repeat", "1"},
        {"view --threads 5000", "--threads", "4096"},
        {"render --size 20000x10", "--size", "16384"},
        {"render --set max_depth=99", "max_depth", "31"},
    };
    for (const Case& c : cases) {
        const CliRun r = run_lucent(c.args);
        EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
        EXPECT_NE(r.output.find(c.flag), std::string::npos) << c.args << "\n" << r.output;
        EXPECT_NE(r.output.find(c.range), std::string::npos) << c.args << "\n" << r.output;
    }
}

}  // namespace

/// Every usage error reads "lucent <command>: what was wrong; the fix", CLI11's own
/// included, and a mistyped command, flag, sample or option gets a "did you mean".
TEST(CliHelp, EveryUsageErrorHasOneStyleAndMistypesAGuess) {
    struct Case {
        const char* args;
        const char* message;  // the whole first line
    };
    const Case cases[] = {
        {"rendr", "lucent: 'rendr' is not a command (did you mean 'render'?); the commands are "
                  "render, view, bench, tea, noise, compare"},
        {"", "lucent: a command is needed: render, view, bench, tea, noise, compare; run `lucent "
             "--help`"},
        {"bench ray", "lucent bench: 'ray' is not a command (did you mean 'rays'?); the commands "
                      "are rays, tea, build, igi, fog, present, spheres, curves"},
        {"render --sampel igi", "lucent render: unknown flag --sampel (did you mean '--sample'?); "
                                "run `lucent render --help`"},
        {"render --spp -3", "lucent render: --spp '-3': expected a number in [0, 1000000]; run "
                            "`lucent render --help`"},
        {"view --threads abc", "lucent view: --threads 'abc': expected a number in [0, 4096]; run "
                               "`lucent view --help`"},
        {"render --size", "lucent render: --size: needs a value (WxH); run `lucent render --help`"},
        {"render stray", "lucent render: unexpected argument 'stray'; run `lucent render --help`"},
        {"render --sample ig", "lucent render: --sample ig: no such sample (did you mean 'igi'?); "
                               "the samples are whitted, direct, igi, radiosity, pathtracer, hair, "
                               "fog"},
    };
    for (const Case& c : cases) {
        const CliRun r = run_lucent(c.args);
        EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
        EXPECT_EQ(r.output.substr(0, r.output.find('\n')), c.message) << c.args;
    }
    const CliRun option = run_lucent("render --sample igi --set vlps=3");
    EXPECT_NE(option.output.find("has no option 'vlps' (did you mean 'vpls'?); its options are"),
              std::string::npos)
        << option.output;
}

TEST(NearestName, TyposAreGuessedAndStrangersAreNot) {
    using lucent::samples::nearest_name;
    const std::vector<std::string> samples = {"whitted", "direct", "igi", "radiosity", "pathtracer"};
    EXPECT_EQ(nearest_name("withted", samples), "whitted");  // a swap of neighbours
    EXPECT_EQ(nearest_name("pathtracr", samples), "pathtracer");
    EXPECT_EQ(nearest_name("ig", samples), "igi");
    EXPECT_EQ(nearest_name("radio", samples), "radiosity");  // the start of one name
    EXPECT_EQ(nearest_name("renderer", samples), "");
    EXPECT_EQ(nearest_name("", samples), "");
    EXPECT_EQ(nearest_name("d", {"direct", "depth"}), "");  // the start of two: no guess
    EXPECT_EQ(lucent::samples::did_you_mean("--sampel", {"--sample", "--scene"}),
              " (did you mean '--sample'?)");
}

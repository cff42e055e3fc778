// Every subcommand's --help shows examples, every benchmark has --json, and unknown flags or
// bad values are refused with a message naming them (exit code 2).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace {

struct CliRun {
    int exit_code = -1;
    std::string output;
};

CliRun lucent(const std::string& args) {
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

const char* const kCommands[] = {"render",    "view",      "bench rays", "bench build", "bench tea",
                                 "bench igi", "bench fog", "tea",        "noise"};

TEST(CliHelp, EverySubcommandShowsExamplesOfItself) {
    for (const char* command : kCommands) {
        const CliRun r = lucent(std::string(command) + " --help");
        EXPECT_EQ(r.exit_code, 0) << command;
        EXPECT_NE(r.output.find("Examples:"), std::string::npos) << command << "\n" << r.output;
        EXPECT_NE(r.output.find(std::string("lucent ") + command + " "), std::string::npos)
            << command << ": no example runs it\n"
            << r.output;
    }
}

TEST(CliHelp, EveryBenchmarkHasJsonOutput) {
    for (const char* bench : {"bench rays", "bench build", "bench tea", "bench igi", "bench fog"}) {
        const CliRun r = lucent(std::string(bench) + " --help");
        EXPECT_NE(r.output.find("--json"), std::string::npos) << bench << "\n" << r.output;
    }
}

TEST(CliHelp, TopLevelHelpListsView) {
    const CliRun r = lucent("--help");
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.output.find("view"), std::string::npos) << r.output;
}

TEST(CliHelp, UnknownFlagsAreNamedForEverySubcommand) {
    for (const char* command : kCommands) {
        const CliRun r = lucent(std::string(command) + " --frobnicate");
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
        const CliRun r = lucent(c.args);
        EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
        EXPECT_NE(r.output.find(c.flag), std::string::npos) << c.args << "\n" << r.output;
        EXPECT_NE(r.output.find(c.range), std::string::npos) << c.args << "\n" << r.output;
    }
}

}  // namespace

// Running another program (the C++ compiler, for modules compiled at run time) without a
// shell: no quoting, no injection through file names.
#pragma once

#include <string>
#include <vector>

namespace lucent::core {

struct ChildResult {
    bool started = false;  // false: the program could not be run (`output` says why)
    int exit_code = -1;    // its exit status; -1 when a signal ended it
    std::string output;    // what it wrote to stdout and stderr
};

/// Runs argv[0] (looked up on PATH) with `argv`, waits for it, and returns its exit status
/// and its output, which goes through the file `output_file` (created, then removed).
ChildResult run_child_process(const std::vector<std::string>& argv, const std::string& output_file);

/// The first of `names` that is an executable file in a folder of $PATH (or, for a name
/// with a '/', that is one itself); empty when none is.
std::string find_executable(const std::vector<std::string>& names);

}  // namespace lucent::core

// "Did you mean ...?": the known name nearest a mistyped one, for the errors of the command
// line (subcommands, flags) and of the samples (--sample, --set names), in C++ and Python.
#pragma once

#include <string>
#include <vector>

namespace lucent::samples {

/// The candidate nearest `typed` by edit distance (Levenshtein: insertions, deletions,
/// substitutions, and swaps of neighbours count one each), when it is near enough to be a
/// typo: at most a third of the longer name, at least one edit. Or the one candidate
/// that `typed` begins. Empty when none is.
std::string nearest_name(const std::string& typed, const std::vector<std::string>& candidates);

/// " (did you mean 'x'?)" for nearest_name, or "".
std::string did_you_mean(const std::string& typed, const std::vector<std::string>& candidates);

}  // namespace lucent::samples

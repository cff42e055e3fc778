// Reads the range a sample option's help text states, "(1..256)", for the viewer's sliders:
// the help is the one place each sample states it, and it is already shown by --help.
#include <cmath>
#include <regex>

#include "samples/sample.h"

namespace lucent::samples {
namespace {

/// "1e6" → 1e6, "2^30" → 2^30.
double number(const std::string& text) {
    const size_t caret = text.find('^');
    if (caret == std::string::npos) return std::stod(text);
    return std::pow(std::stod(text.substr(0, caret)), std::stod(text.substr(caret + 1)));
}

}  // namespace

bool option_range(const SampleOption& option, double& lo, double& hi) {
    static const std::regex range(
        R"(\(\s*(-?[0-9]+(?:\.[0-9]+)?(?:e[+-]?[0-9]+)?(?:\^[0-9]+)?)\s*\.\.\s*)"
        R"((-?[0-9]+(?:\.[0-9]+)?(?:e[+-]?[0-9]+)?(?:\^[0-9]+)?))");
    std::smatch m;
    if (!std::regex_search(option.help, m, range)) return false;
    lo = number(m[1].str());
    hi = number(m[2].str());
    return lo < hi;
}

}  // namespace lucent::samples

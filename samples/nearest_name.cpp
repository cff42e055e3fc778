#include "samples/nearest_name.h"

#include <algorithm>

namespace lucent::samples {

namespace {

/// Optimal string alignment distance (Damerau-Levenshtein without repeated edits of a
/// substring): the usual measure of a typo.
size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
    for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (size_t i = 1; i <= a.size(); ++i)
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    return d[a.size()][b.size()];
}

}  // namespace

std::string nearest_name(const std::string& typed, const std::vector<std::string>& candidates) {
    if (typed.empty()) return "";
    std::string best;
    size_t best_distance = ~size_t(0);
    for (const std::string& c : candidates) {
        const size_t distance = edit_distance(typed, c);
        const size_t allowed = std::max<size_t>(1, std::max(typed.size(), c.size()) / 3);
        if (distance <= allowed && distance < best_distance) {
            best = c;
            best_distance = distance;
        }
    }
    if (!best.empty()) return best;
    std::string prefixed;
    for (const std::string& c : candidates) {
        if (c.rfind(typed, 0) != 0) continue;
        if (!prefixed.empty()) return "";  // the start of several: no guess
        prefixed = c;
    }
    return prefixed;
}

std::string did_you_mean(const std::string& typed, const std::vector<std::string>& candidates) {
    const std::string nearest = nearest_name(typed, candidates);
    return nearest.empty() ? "" : " (did you mean '" + nearest + "'?)";
}

}  // namespace lucent::samples

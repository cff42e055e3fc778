#include "bench/common/ray_checksums.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace lucent::bench {

std::string checksum_differences(const RayChecksums& a, const RayChecksums& b, const char* a_name,
                                 const char* b_name) {
    std::string out;
    auto add = [&](const char* what, double x, double y, bool ok) {
        if (ok) return;
        char buf[200];
        std::snprintf(buf, sizeof buf, "%s%s %.9g (%s) vs %.9g (%s)", out.empty() ? "" : ", ", what,
                      x, a_name, y, b_name);
        out += buf;
    };
    auto close = [](double x, double y) {
        return std::fabs(x - y) <= 1e-6 * std::max(std::fabs(x), std::fabs(y));
    };
    add("primary hits", double(a.primary_hits), double(b.primary_hits),
        a.primary_hits == b.primary_hits);
    add("primary sum_t", a.primary_sum_t, b.primary_sum_t, close(a.primary_sum_t, b.primary_sum_t));
    add("shadow occluded", double(a.occluded), double(b.occluded), a.occluded == b.occluded);
    add("diffuse hits", double(a.diffuse_hits), double(b.diffuse_hits),
        a.diffuse_hits == b.diffuse_hits);
    add("diffuse sum_t", a.diffuse_sum_t, b.diffuse_sum_t, close(a.diffuse_sum_t, b.diffuse_sum_t));
    return out;
}

}  // namespace lucent::bench

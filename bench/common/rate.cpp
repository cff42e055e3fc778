#include "bench/common/rate.h"

#include <algorithm>
#include <cstdio>

namespace lucent::bench {

double median_of(std::vector<double> values) {
    if (values.empty()) return 0;
    std::sort(values.begin(), values.end());
    const size_t m = values.size();
    return m % 2 ? values[m / 2] : 0.5 * (values[m / 2 - 1] + values[m / 2]);
}

Rate rate_of(const std::vector<double>& values) {
    Rate r;
    if (values.empty()) return r;
    r.median = median_of(values);
    r.min = *std::min_element(values.begin(), values.end());
    r.max = *std::max_element(values.begin(), values.end());
    return r;
}

double median_ratio(const Rate& a, const Rate& b) {
    return b.median > 0 ? a.median / b.median : 0.0;
}

std::string rate_text(const Rate& rate) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "%.2f Mrays/s (min %.2f, max %.2f)", rate.median, rate.min,
                  rate.max);
    return buf;
}

}  // namespace lucent::bench

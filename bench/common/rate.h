// Figures of timed repeats: the median and the spread, the way every benchmark reports them.
#pragma once

#include <string>
#include <vector>

namespace lucent::bench {

/// Mrays/s (or any rate) over the timed repeats: median, min, max.
struct Rate {
    double median = 0, min = 0, max = 0;
};

/// The median (the mean of the middle two of an even count); 0 for none.
double median_of(std::vector<double> values);

/// Median, min and max of `values`; all 0 for none.
Rate rate_of(const std::vector<double>& values);

/// a's median over b's (0 when b has none).
double median_ratio(const Rate& a, const Rate& b);

/// "12.34 Mrays/s (min 12.00, max 12.50)".
std::string rate_text(const Rate& rate);

}  // namespace lucent::bench

#include "bench/common/report.h"

#include <cmath>
#include <cstdio>

namespace lucent::bench {

double rounded(double value, int decimals) {
    if (!std::isfinite(value)) return value;  // nlohmann-json writes null for these
    const double scale = std::pow(10.0, decimals);
    return std::round(value * scale) / scale;
}

Json rate_json(const Rate& rate) {
    return Json{{"mrays", rounded(rate.median, 4)},
                {"min", rounded(rate.min, 4)},
                {"max", rounded(rate.max, 4)}};
}

std::string json_text(const Json& document) {
    // A path need not be UTF-8: its invalid bytes become U+FFFD rather than an exception.
    return document.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

namespace {
thread_local JsonCapture* t_capture = nullptr;  // the innermost living capture
}  // namespace

JsonCapture::JsonCapture() : m_outer(t_capture) {
    t_capture = this;
}
JsonCapture::~JsonCapture() {
    t_capture = m_outer;
}

void print_json(const Json& document) {
    const std::string text = json_text(document);
    if (t_capture) {
        t_capture->m_text = text;
        return;
    }
    std::fwrite(text.data(), 1, text.size(), stdout);
}

}  // namespace lucent::bench

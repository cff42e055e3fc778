#include "progress_bar.h"

#include <unistd.h>

#include <cstdio>

namespace lucent::cli {

ProgressBar::ProgressBar(std::string label, std::string unit,
                         std::chrono::milliseconds show_after)
    : m_label(std::move(label)),
      m_unit(std::move(unit)),
      m_enabled(::isatty(STDERR_FILENO) != 0),
      m_show_after(show_after),
      m_start(std::chrono::steady_clock::now()),
      m_last(m_start) {}

ProgressBar::~ProgressBar() {
    finish();
}

void ProgressBar::update(unsigned long long done, unsigned long long total) {
    if (!m_enabled || total == 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (!m_updated) {
        m_updated = true;
        m_first = now;
    }
    if (!m_started || done < m_last_done) {
        m_started = true;
        m_start = now;
        m_first_done = done;
    }
    m_last_done = done;
    if (now - m_first < m_show_after) return;
    if (m_drawn && done < total && now - m_last < std::chrono::milliseconds(100)) return;
    m_last = now;
    const double elapsed = std::chrono::duration<double>(now - m_start).count();
    const double rate = elapsed > 0 ? double(done - m_first_done) / elapsed : 0;
    const double left = rate > 0 ? double(total - done) / rate : 0;
    constexpr int kWidth = 30;
    const int filled = int(kWidth * double(done) / double(total));
    char timing[64] = "";
    if (rate > 0)  // none yet at the first update
        std::snprintf(timing, sizeof timing, ", %.1f %s/s, %.0f s left", rate, m_unit.c_str(), left);
    std::fprintf(stderr, "\r%s [%.*s%*s] %llu/%llu %s%s  ", m_label.c_str(), filled,
                 "##############################", kWidth - filled, "", done, total,
                 m_unit.c_str(), timing);
    std::fflush(stderr);
    m_drawn = true;
}

void ProgressBar::finish() {
    if (!m_drawn) return;
    std::fprintf(stderr, "\r%*s\r", 100, "");
    std::fflush(stderr);
    m_drawn = false;
}

}  // namespace lucent::cli

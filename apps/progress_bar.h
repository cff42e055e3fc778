// A one-line progress bar with rate and time left, on stderr, only when stderr is a
// terminal (so logs and pipes stay clean).
#pragma once

#include <chrono>
#include <string>

namespace lucent::cli {

class ProgressBar {
  public:
    /// `unit` names what is counted ("launches", "MB").
    ProgressBar(std::string label, std::string unit);
    ~ProgressBar();
    /// Shows `done` of `total`; redraws at most ten times a second.
    void update(unsigned long long done, unsigned long long total);
    /// Clears the line.
    void finish();

  private:
    std::string m_label, m_unit;
    bool m_enabled;
    bool m_drawn = false;
    std::chrono::steady_clock::time_point m_start, m_last;
};

}  // namespace lucent::cli

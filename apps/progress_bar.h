// A one-line progress bar with rate and time left, on stderr, only when stderr is a
// terminal (so logs and pipes stay clean).
#pragma once

#include <chrono>
#include <string>
#include <utility>

namespace lucent::cli {

class ProgressBar {
  public:
    /// `unit` names what is counted ("launches", "MB"). Nothing is drawn until `show_after`
    /// has passed since the first update: work that ends sooner leaves no line behind.
    ProgressBar(std::string label, std::string unit,
                std::chrono::milliseconds show_after = std::chrono::milliseconds(0));
    ~ProgressBar();
    /// Shows `done` of `total`; redraws at most ten times a second.
    void update(unsigned long long done, unsigned long long total);
    /// Clears the line.
    void finish();
    /// Names what is being done from the next update on (a loader's stages).
    void set_label(std::string label) { m_label = std::move(label); }
    /// Whether it draws at all (stderr is a terminal).
    bool enabled() const { return m_enabled; }

  private:
    std::string m_label, m_unit;
    bool m_enabled;
    bool m_drawn = false;
    std::chrono::milliseconds m_show_after;
    bool m_updated = false;                           // any update yet
    std::chrono::steady_clock::time_point m_first;   // the first update's time
    // The rate is measured from the first update (not from construction, which may be long
    // before the work starts) and again from each restart (done going back: a new launch).
    bool m_started = false;
    unsigned long long m_first_done = 0, m_last_done = 0;
    std::chrono::steady_clock::time_point m_start, m_last;
};

/// Runs `bench(options)` (a `lucent bench` subcommand) with a progress bar fed from
/// options.progress, except for JSON output, which stays one clean object. Returns its code.
template <class Options, class Bench>
int run_with_progress_bar(const char* label, const char* unit, Options& options, Bench&& bench) {
    ProgressBar bar(label, unit);
    if (!options.json)
        options.progress = [&bar](unsigned done, unsigned total) { bar.update(done, total); };
    return std::forward<Bench>(bench)(options);  // the bar's destructor clears its line
}

}  // namespace lucent::cli

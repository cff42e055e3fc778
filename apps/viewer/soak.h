// `lucent view --soak SECONDS`: the viewer driven as a user would drive it for that long (the
// window resized through a cycle of sizes, from 1x1 to 1280x720, the camera orbited, zoomed
// and panned, the panel, the key list, the denoiser and the sample's options switched), with
// the render following the window's size, checking every frame and the process's resident
// memory. Issue 26's soak of the viewer; CI runs a short one (tests/view_test.cpp).
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "render_worker.h"
#include "samples/sample.h"
#include "scene/camera_controller.h"

namespace lucent::viewer {

class Window;

/// One step of the soak's cycle: a window size, and whether the panel (and the F1 list)
/// covers part of it, when its frame is checked for its size only.
struct CycleStep {
    int width, height;
    bool panel, keys;
};

/// What the soak drives: the viewer loop's own window, worker, camera and switches.
struct SoakTargets {
    Window& window;
    RenderWorker& worker;
    scene::CameraController& camera;
    bool& show_panel;
    bool& show_keys;  // the F1 list
};

/// The soak's steps, checks and figures. A cycle visits every size once, the last its home:
/// the starting size, camera, options and denoiser, whose frame must equal the first cycle's.
/// Memory is measured at the end of each cycle (so always in the same state), taken as the
/// baseline after the warm-up cycles, and must stay within kMemoryBound of it to the end.
class Soak {
  public:
    using Clock = std::chrono::steady_clock;

    /// Takes the starting memory figure; call it before the window opens.
    Soak(double seconds, const samples::Sample& sample, const samples::RenderSettings& settings,
         samples::ViewDenoiser denoiser);

    /// Once per window frame, before it is drawn (once the session is open): ends the step
    /// whose frame was checked and starts the next (a new window size and the user's moves),
    /// or drags the camera on.
    void drive(const SoakTargets& targets, const WorkerStatus& status);
    /// Once per window frame after it was drawn, before the swap. `texture_holds_shown`: the
    /// window's image is `shown` (no partial frame was drawn over it since). Compares the
    /// window with the frame once per frame when the image fills it (panel hidden, the
    /// render at the window's size).
    void check(const ShownFrame& shown, bool texture_holds_shown, int fb_width, int fb_height,
               bool overlay_shown);
    /// True when the time is up (at the end of a cycle) or a check failed.
    bool done() const { return m_done; }
    /// Prints the figures and the verdict; returns the exit code (0 passed, 1 failed).
    int finish(uint64_t window_frames, uint64_t frames_rendered);

  private:
    struct OptionFlip {
        std::string name, initial, other, current;
    };
    bool home_step() const { return m_step_in_cycle + 1 == m_steps_of_cycle.size(); }
    void start_step(const SoakTargets& targets, const WorkerStatus& status);
    void end_cycle();
    void fail(const std::string& why);
    double elapsed() const;

    double m_seconds;
    std::vector<CycleStep> m_steps_of_cycle;  // the last: the starting size (home)
    std::vector<OptionFlip> m_options;
    samples::ViewDenoiser m_initial_denoiser, m_denoiser;
    unsigned m_initial_spp;
    Clock::time_point m_start, m_step_start, m_next_figure;

    bool m_started = false, m_done = false;
    size_t m_step_in_cycle = 0;
    uint64_t m_steps = 0, m_cycles = 0;
    unsigned m_step_window_frames = 0;
    bool m_step_checked = false;  // this step's frame reached the window at its size
    bool m_progressive = false;
    int m_fb_width = 0, m_fb_height = 0;
    unsigned m_fb_stable_frames = 0;  // window frames drawn since the size last changed
    uint64_t m_last_compared = 0;     // the last frame number compared with the window

    std::vector<unsigned char> m_home_image;  // the first cycle's frame at home
    unsigned m_home_width = 0, m_home_height = 0;
    uint64_t m_frames_compared = 0, m_home_compared = 0, m_sizes_followed = 0;

    uint64_t m_rss_start = 0, m_rss_warm = 0, m_rss_end = 0, m_rss_peak = 0;
    std::string m_failure;
};

}  // namespace lucent::viewer

#include "soak.h"

#include <algorithm>
#include <cstdio>

#include "resident_memory.h"
#include "window.h"
#include "window_readback.h"

namespace lucent::viewer {
namespace {

/// The steps of one cycle before the home (starting) size ends it: a single pixel, odd
/// sides, thin and tall, up to 1280x720 (a 1280x1024 Xvfb screen holds them all), and a
/// change of the width alone and of the height alone (a texture resized by one side only
/// would show the wrong pixels).
constexpr CycleStep kCycle[] = {
    {1, 1, false, false},    {1280, 720, true, false}, {17, 9, false, false},
    {640, 9, false, false},  {640, 480, false, false}, {333, 211, true, true},
    {64, 720, false, false}, {1024, 7, true, false},   {801, 599, false, false},
};

/// Cycles before the memory baseline: every size, switch, denoiser and option value has been
/// seen twice, so the allocators' pools, Mesa's compiled shader variants and the scene
/// rebuilds an option asks for have reached their size (the path tracer's memory fell by 7
/// MiB from the first cycle's end to the second's, then stayed: docs/testing.md).
constexpr uint64_t kWarmUpCycles = 2;
/// Cycles after the warm-up before the soak may end, however short SECONDS is: one is
/// enough for a leak on resize to pass the bound (below).
constexpr uint64_t kMeasuredCycles = 1;

/// Resident memory may grow by this much from the end of the warm-up to the end (both
/// measured at the end of a cycle: the same window size, camera and options, after
/// malloc_trim). Measured without a leak (docs/testing.md): +0.01 MiB over 10 minutes of
/// whitted, +0.03 over 2 minutes of the path tracer, the figures of single cycles within
/// 0.03 of each other; the bound leaves room for small blocks' allocator slack. A leak of what a
/// resize replaces fails it within a cycle: one cycle's sizes hold 1.84 million pixels besides the
/// home size, so the window's texture or pixel-buffer storage leaked at each resize is 7 MiB a
/// cycle (RGBA8), the render's float4 output 28 MiB, and a leaked session (the scene, its BVH and
/// compiled programs) more.
constexpr uint64_t kMemoryBound = 4u << 20;

/// A step's frame must reach the window within this (a render at 1280x720 on one slow
/// CPU core, the scene rebuilt for the new size, is a few seconds).
constexpr double kStepTimeoutSeconds = 120;
/// Each step lasts at least this many window frames: the camera is dragged over the first
/// of them, and the drawable has taken its new size after two.
constexpr unsigned kMinStepWindowFrames = 6;
constexpr unsigned kDragWindowFrames = 4;
constexpr float kDragRadians = 0.02f;

double mib(uint64_t bytes) {
    return double(bytes) / double(1u << 20);
}

std::string size_text(int w, int h) {
    return std::to_string(w) + "x" + std::to_string(h);
}

}  // namespace

Soak::Soak(double seconds, const samples::Sample& sample, const samples::RenderSettings& settings,
           samples::ViewDenoiser denoiser)
    : m_seconds(seconds),
      m_initial_denoiser(denoiser),
      m_denoiser(denoiser),
      m_initial_spp(settings.spp),
      m_start(Clock::now()) {
    return_large_blocks_when_freed();
    m_rss_start = resident_bytes();
    m_steps_of_cycle.assign(std::begin(kCycle), std::end(kCycle));
    m_steps_of_cycle.push_back({int(settings.width), int(settings.height), false, false});
    // Switches flip; integers go to another value of their range. Numbers and text stay
    // (the panel's sliders and fields reach the same set_option).
    for (const samples::SampleOption& o : sample.options) {
        const auto given = settings.sets.find(o.name);
        const std::string initial = given != settings.sets.end() ? given->second : o.default_value;
        std::string other;
        if (o.kind == samples::OptionKind::kSwitch) {
            other = std::string(initial == "1" ? "0" : "1");
        } else if (o.kind == samples::OptionKind::kInteger && o.hi > o.lo) {
            const long value = std::stol(initial), lo = long(o.lo);
            other = std::to_string(value == lo ? lo + 1 : lo);
        } else {
            continue;
        }
        m_options.push_back({o.name, initial, other, initial});
    }
    std::printf("lucent view: soak: %.0f s of %s; a cycle resizes the window to", seconds,
                sample.name.c_str());
    for (const CycleStep& step : m_steps_of_cycle)
        std::printf(" %s", size_text(step.width, step.height).c_str());
    std::printf(" (the last: the start, compared with the first cycle's frame)\n");
    std::printf("lucent view: soak: resident memory start %.2f MiB\n", mib(m_rss_start));
    std::fflush(stdout);
}

double Soak::elapsed() const {
    return std::chrono::duration<double>(Clock::now() - m_start).count();
}

void Soak::fail(const std::string& why) {
    if (m_failure.empty()) m_failure = why;
    m_done = true;
}

void Soak::drive(const SoakTargets& targets, const WorkerStatus& status) {
    if (m_done) return;
    if (!m_started) {
        m_started = true;
        m_progressive = status.progressive;
        start_step(targets, status);
        return;
    }
    ++m_step_window_frames;
    if (!home_step() && m_step_window_frames <= kDragWindowFrames) {
        // A left-drag over a few window frames, as a hand moves the mouse.
        targets.camera.orbit(kDragRadians, 0.5f * kDragRadians);
        targets.worker.set_camera(targets.camera.camera());
    }
    if (m_step_checked && m_step_window_frames >= kMinStepWindowFrames) {
        ++m_sizes_followed;
        if (home_step()) end_cycle();
        if (m_done) return;
        m_step_in_cycle = (m_step_in_cycle + 1) % m_steps_of_cycle.size();
        start_step(targets, status);
    } else if (std::chrono::duration<double>(Clock::now() - m_step_start).count() >
               kStepTimeoutSeconds) {
        const CycleStep& step = m_steps_of_cycle[m_step_in_cycle];
        fail("the window is " + size_text(m_fb_width, m_fb_height) + " (asked for " +
             size_text(step.width, step.height) + ") but no frame of that size reached it in " +
             std::to_string(int(kStepTimeoutSeconds)) +
             " s: the render does not follow the window");
    }
}

void Soak::start_step(const SoakTargets& targets, const WorkerStatus& status) {
    ++m_steps;
    m_step_window_frames = 0;
    m_step_checked = false;
    m_step_start = Clock::now();
    const CycleStep& step = m_steps_of_cycle[m_step_in_cycle];
    targets.window.set_size(step.width, step.height);
    scene::CameraController& camera = targets.camera;
    if (home_step()) {
        // Everything as it started: the frame must be the first cycle's again.
        camera.reset();
        for (OptionFlip& o : m_options)
            if (o.current != o.initial) targets.worker.set_option(o.name, o.current = o.initial);
        if (status.denoises && m_denoiser != m_initial_denoiser)
            targets.worker.set_denoiser(m_denoiser = m_initial_denoiser);
        // One sample per pixel, so the frame compared is the same one every cycle.
        if (m_progressive) targets.worker.set_spp_limit(1);
        targets.show_panel = false;
        targets.show_keys = false;
    } else {
        const float sign = m_steps % 2 ? 1.0f : -1.0f;
        camera.orbit(0.3f, 0.05f * sign);
        camera.zoom(sign > 0 ? 0.85f : 1 / 0.85f);
        camera.pan(0.02f * sign, -0.01f);
        targets.show_panel = step.panel;
        targets.show_keys = step.keys;
        if (status.denoises)
            targets.worker.set_denoiser(m_denoiser = samples::next_view_denoiser(m_denoiser));
        if (!m_options.empty()) {
            OptionFlip& o = m_options[m_steps % m_options.size()];
            o.current = o.current == o.initial ? o.other : o.initial;
            targets.worker.set_option(o.name, o.current);
        }
        if (m_progressive) targets.worker.set_spp_limit(m_initial_spp);
    }
    targets.worker.set_camera(camera.camera());
}

void Soak::check(const ShownFrame& shown, bool texture_holds_shown, int fb_width, int fb_height,
                 bool overlay_shown) {
    if (m_done || !m_started) return;
    if (fb_width != m_fb_width || fb_height != m_fb_height) {
        m_fb_width = fb_width;
        m_fb_height = fb_height;
        m_fb_stable_frames = 0;
        return;
    }
    ++m_fb_stable_frames;
    // The render follows the window: until a frame of its size arrives, the last one is
    // shown scaled.
    if (shown.number == 0 || int(shown.width) != fb_width || int(shown.height) != fb_height) return;
    // Mesa gives the drawable its new size at the swap after the resize.
    if (m_fb_stable_frames < 2) return;
    if (overlay_shown) {
        m_step_checked = true;  // the panel covers part of the image: its size is the check
        return;
    }
    if (!texture_holds_shown || shown.number == m_last_compared) return;
    m_last_compared = shown.number;
    const std::vector<unsigned char> rendered = shown.display->rgba();
    const size_t differ = count_differing_rgb(read_window_rgba(fb_width, fb_height), rendered);
    ++m_frames_compared;
    m_step_checked = true;
    if (differ > 0)
        return fail("frame " + std::to_string(shown.number) + " at " +
                    size_text(fb_width, fb_height) + ": " + std::to_string(differ) + " of " +
                    std::to_string(rendered.size() / 4) +
                    " window pixels differ from the rendered image");
    // The home frame: one sample per pixel (progressive), everything as at the start.
    if (!home_step() || (m_progressive && shown.samples != 1)) return;
    if (m_home_image.empty()) {
        m_home_image = rendered;
        m_home_width = shown.width;
        m_home_height = shown.height;
        return;
    }
    if (shown.width != m_home_width || shown.height != m_home_height) return;
    const size_t changed = count_differing_rgb(m_home_image, rendered);
    ++m_home_compared;
    if (changed > 0)
        fail("cycle " + std::to_string(m_cycles + 1) + ": back at the start (" +
             size_text(fb_width, fb_height) + ", the first camera, options and denoiser), " +
             std::to_string(changed) + " pixels differ from the first cycle's frame");
}

void Soak::end_cycle() {
    ++m_cycles;
    const uint64_t rss = resident_bytes();
    const double t = elapsed();
    const double figure_interval = std::max(1.0, m_seconds / 10);
    if (m_cycles == kWarmUpCycles) {
        m_rss_warm = m_rss_peak = rss;
        std::printf(
            "lucent view: soak: resident memory after warm-up (cycle %llu, %.1f s) %.2f MiB\n",
            (unsigned long long)m_cycles, t, mib(rss));
        m_next_figure = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(figure_interval));
    } else if (m_cycles > kWarmUpCycles) {
        m_rss_peak = std::max(m_rss_peak, rss);
        if (t >= m_seconds && m_cycles >= kWarmUpCycles + kMeasuredCycles) {
            m_rss_end = rss;
            m_done = true;
        } else if (Clock::now() >= m_next_figure) {
            std::printf("lucent view: soak: resident memory at cycle %llu (%.1f s) %.2f MiB\n",
                        (unsigned long long)m_cycles, t, mib(rss));
            m_next_figure += std::chrono::duration_cast<Clock::duration>(
                std::chrono::duration<double>(figure_interval));
        }
    }
    std::fflush(stdout);
}

int Soak::finish(uint64_t window_frames, uint64_t frames_rendered) {
    const double t = elapsed();
    if (m_failure.empty() && m_rss_end == 0)
        fail("the window was closed after " + std::to_string(int(t)) + " s, before the soak ended");
    if (m_rss_end > 0) {
        const double growth = mib(m_rss_end) - mib(m_rss_warm);
        std::printf(
            "lucent view: soak: resident memory end (cycle %llu, %.1f s) %.2f MiB, peak "
            "after warm-up %.2f MiB, growth after warm-up %+.2f MiB (bound %.1f MiB)\n",
            (unsigned long long)m_cycles, t, mib(m_rss_end), mib(m_rss_peak), growth,
            mib(kMemoryBound));
#if defined(__SANITIZE_ADDRESS__)
        // AddressSanitizer's quarantine holds freed blocks (up to 256 MB) to catch uses after
        // free: resident memory grows with every free, so it says nothing about leaks here.
        std::printf("lucent view: soak: memory bound not checked (AddressSanitizer build)\n");
#else
        if (m_failure.empty() && m_rss_end > m_rss_warm + kMemoryBound)
            fail("resident memory grew by " + std::to_string(growth).substr(0, 6) +
                 " MiB after the warm-up, more than the bound of " +
                 std::to_string(kMemoryBound >> 20) + " MiB: something leaks");
#endif
    }
    std::printf(
        "lucent view: soak: %llu cycles, %llu window sizes followed, %llu window frames, "
        "%llu frames rendered, %llu compared with the window, %llu back at the start "
        "equal to the first cycle's\n",
        (unsigned long long)m_cycles, (unsigned long long)m_sizes_followed,
        (unsigned long long)window_frames, (unsigned long long)frames_rendered,
        (unsigned long long)m_frames_compared, (unsigned long long)m_home_compared);
    if (!m_failure.empty()) {
        std::fflush(stdout);
        std::fprintf(stderr, "lucent view: soak: FAILED: %s\n", m_failure.c_str());
        return 1;
    }
    std::printf("lucent view: soak: passed\n");
    return 0;
}

}  // namespace lucent::viewer

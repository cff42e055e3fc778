// The viewer's loop: input moves the camera, the worker renders, the newest finished frame is
// uploaded and drawn, the panel on top. The loop never waits for a render, so the window
// stays responsive however slow a frame is (the CPU backend shows the last finished frame).
#include "viewer.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "camera_flags.h"
#include "input.h"
#include "key_bindings.h"
#include "panel.h"
#include "present/gl.h"
#include "present/image_view.h"
#include "render_worker.h"
#include "screenshot.h"
#include "soak.h"
#include "window.h"

namespace lucent::viewer {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
}

/// The blog's toggles (Radiosity demo): L show VPLs, I GI, M merging.
const char* toggled_option(KeyAction action) {
    switch (action) {
        case KeyAction::kToggleVpls:
            return "show_vpls";
        case KeyAction::kToggleGi:
            return "gi";
        case KeyAction::kToggleMerge:
            return "merge";
        default:
            return nullptr;
    }
}

/// A file name in the working directory that does not exist yet.
std::string next_screenshot_name(const std::string& sample) {
    for (int i = 1;; ++i) {
        const std::string name = "lucent-view-" + sample + "-" + std::to_string(i) + ".png";
        if (!std::filesystem::exists(name)) return name;
    }
}

/// Frames per second over a sliding second: what the panel shows.
class RateMeter {
  public:
    void tick(Clock::time_point now) {
        m_times.push_back(now);
        while (!m_times.empty() && seconds_between(m_times.front(), now) > 1.0)
            m_times.erase(m_times.begin());
    }
    double rate(Clock::time_point now) const {
        if (m_times.size() < 2) return 0;
        const double span = std::max(seconds_between(m_times.front(), now), 1e-3);
        return double(m_times.size() - 1) / span;
    }

  private:
    std::vector<Clock::time_point> m_times;
};

}  // namespace

int run_viewer(const ViewerConfig& config) {
    const samples::Sample& sample = *config.sample;
    const bool headless_check = config.frames > 0;
    // Its starting memory figure before the window's.
    std::optional<Soak> soak;
    if (config.soak > 0) soak.emplace(config.soak, sample, config.settings, config.denoiser);
    const bool fit_window = config.fit_window || soak;
    Window window("lucent view: " + sample.name, int(config.settings.width),
                  int(config.settings.height), /*exact=*/headless_check || soak);
    Input input(window.handle());
    window.start_ui(config.ui_scale);
    ImageView view;
    RenderWorker worker(sample, config.settings, config.frames, config.denoiser);

    std::optional<scene::CameraController> camera;
    ShownFrame shown;
    PanelState panel;
    bool show_panel = config.panel;
    bool show_keys = false;   // the F1 list
    bool copy_flags = false;  // the panel's button, applied in the next frame's key handling
    float panel_size[2] = {0, 0};
    RateMeter ui_rate, render_rate;
    const Clock::time_point start = Clock::now();
    Clock::time_point last = start;
    uint64_t ui_frames = 0;
    uint64_t partial_version = 0, partial_uploads = 0;
    Clock::time_point last_partial = start;
    constexpr double kPartialInterval = 0.1;  // seconds
    std::vector<double> ui_frame_ms;  // intervals between window frames, for --verbose
    int exit_code = 0;
    int last_fb_width = 0, last_fb_height = 0;
    // The size the render was last asked for (--fit-window): the window's at the start.
    int render_width = int(config.settings.width), render_height = int(config.settings.height);
    bool texture_holds_shown = false;  // no partial frame drawn over the shown one

    while (!window.should_close()) {
        // Up to 60 window frames/s while idle; input wakes it at once.
        window.wait_events(1.0 / 60.0);
        const Clock::time_point now = Clock::now();
        const float dt = float(seconds_between(last, now));
        // Only for --verbose's figures at exit: kept for every frame, the list grew by 8 bytes a
        // frame for as long as the window was open (the soak found it: 0.26 MiB in 10 minutes).
        if (config.verbose && ui_frames > 0) ui_frame_ms.push_back(1000.0 * dt);
        last = now;
        ui_rate.tick(now);
        ++ui_frames;

        const WorkerStatus status = worker.status();
        if (!camera && status.opened) camera.emplace(status.initial_camera);
        const ImGuiIO& io = ImGui::GetIO();
        if (camera && input.move_camera(*camera, dt, io.WantCaptureMouse, io.WantCaptureKeyboard))
            worker.set_camera(camera->camera());

        for (int key : input.take_presses()) {
            if (io.WantCaptureKeyboard) break;
            const KeyAction action = action_of_key(key);
            switch (action) {
                case KeyAction::kQuit:
                    window.close();
                    break;
                case KeyAction::kTogglePanel:
                    show_panel = !show_panel;
                    break;
                case KeyAction::kToggleKeys:
                    show_keys = !show_keys;
                    break;
                case KeyAction::kReset:
                    worker.reset();
                    panel.message = "accumulation reset";
                    break;
                case KeyAction::kCameraBack:
                    if (camera) {
                        camera->reset();
                        worker.set_camera(camera->camera());
                    }
                    break;
                case KeyAction::kCopyFlags:
                    copy_flags = true;
                    break;
                case KeyAction::kNextDenoiser:
                    if (!status.denoises) {
                        panel.message =
                            "the " + sample.name + " sample has no denoiser (pathtracer has)";
                    } else {
                        const auto next = samples::next_view_denoiser(status.denoiser);
                        worker.set_denoiser(next);
                        panel.message =
                            std::string("denoiser ") + samples::view_denoiser_name(next);
                    }
                    break;
                case KeyAction::kSavePng:
                    if (shown.number == 0) {
                        panel.message = "nothing rendered yet to save";
                    } else {
                        const std::string name = next_screenshot_name(sample.name);
                        try {
                            scene::write_png_rgba8(name, shown.width, shown.height,
                                                   shown.display->rgba());
                            panel.message = "saved " + name;
                        } catch (const std::exception& e) {
                            panel.message = e.what();
                        }
                    }
                    std::printf("%s\n", panel.message.c_str());
                    break;
                default:
                    break;
            }
            if (const char* option = toggled_option(action)) {
                const bool has = std::any_of(sample.options.begin(), sample.options.end(),
                                             [&](const auto& o) { return o.name == option; });
                if (!has) {
                    panel.message = "the " + sample.name + " sample has no option '" +
                                    std::string(option) + "' (radiosity has)";
                } else {
                    auto it = status.sets.find(option);
                    std::string value = "0";
                    for (const auto& o : sample.options)
                        if (o.name == option) value = o.default_value;
                    if (it != status.sets.end()) value = it->second;
                    const std::string flipped = value == "1" ? "0" : "1";
                    worker.set_option(option, flipped);
                    panel.message = std::string(option) + "=" + flipped;
                }
            }
        }
        if (copy_flags && camera) {
            // On the clipboard and stdout: pasted after `lucent render`, it renders this view.
            const std::string flags = cli::camera_flags(camera->camera());
            glfwSetClipboardString(window.handle(), flags.c_str());
            std::printf("%s\n", flags.c_str());
            std::fflush(stdout);
            panel.message = "copied the camera as flags";
        }
        copy_flags = false;
        if (soak && camera)
            soak->drive(SoakTargets{window, worker, *camera, show_panel, show_keys}, status);

        if (std::optional<ShownFrame> frame = worker.frame_after(shown.number)) {
            shown = std::move(*frame);
            const Clock::time_point before = Clock::now();
            view.show(*shown.display);
            panel.present_ms = 1000.0 * seconds_between(before, Clock::now());
            panel.presentation = view.presentation();
            render_rate.tick(now);
            texture_holds_shown = true;
        } else if (seconds_between(last_partial, now) >= kPartialInterval) {
            // A slow frame in progress (the CPU): its finished rows over the last frame, at
            // most 10 times a second (a 2048x2048 upload costs the window a frame).
            if (auto partial = worker.partial_after(shown.number, partial_version)) {
                view.upload(partial->rgba.data(), partial->width, partial->height);
                texture_holds_shown = false;
                ++partial_uploads;
                last_partial = now;
            }
        }
        if ((headless_check || soak) && !status.error.empty() && !status.busy) {
            std::fprintf(stderr, "lucent view: error: %s\n", status.error.c_str());
            exit_code = 1;
            break;
        }

        int fb_width = 0, fb_height = 0;
        window.framebuffer_size(fb_width, fb_height);
        last_fb_width = fb_width;
        last_fb_height = fb_height;
        if (fit_window && fb_width > 0 && fb_height > 0 &&
            (fb_width != render_width || fb_height != render_height)) {
            // Resizing the window resizes the render (a minimised one keeps its last).
            render_width = fb_width;
            render_height = fb_height;
            worker.set_size(unsigned(fb_width), unsigned(fb_height));
        }
        glViewport(0, 0, fb_width, fb_height);
        glClearColor(0.08f, 0.08f, 0.09f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        view.draw(fb_width, fb_height);
        window.begin_ui_frame();
        if (show_panel) {
            panel.ui_fps = ui_rate.rate(now);
            panel.render_fps = render_rate.rate(now);
            panel.frame = &shown;
            panel.camera = camera ? &camera->camera() : nullptr;
            const PanelChanges changes = draw_panel(sample, status, panel, panel_size);
            for (const auto& [name, value] : changes.options) worker.set_option(name, value);
            if (changes.spp_limit) worker.set_spp_limit(*changes.spp_limit);
            if (changes.denoiser) worker.set_denoiser(*changes.denoiser);
            copy_flags = changes.copy_flags;
        }
        if (show_keys) draw_key_list();
        window.end_ui_frame();

        if (soak) {
            soak->check(shown, texture_holds_shown, fb_width, fb_height, show_panel || show_keys);
            if (soak->done()) break;
        }
        if (headless_check && shown.number >= config.frames) {
            // What the window shows now, before the swap: the back buffer just drawn.
            if (!config.screenshot.empty())
                save_framebuffer(config.screenshot, fb_width, fb_height);
            break;
        }
        window.swap();
    }

    const double elapsed = seconds_between(start, Clock::now());
    if (config.verbose && !ui_frame_ms.empty()) {
        const WorkerStatus status = worker.status();
        std::sort(ui_frame_ms.begin(), ui_frame_ms.end());
        const auto at = [&](double q) {
            return ui_frame_ms[size_t(q * double(ui_frame_ms.size() - 1))];
        };
        std::printf(
            "lucent view: %s on %s; window %llu frames in %.2f s (%.1f frames/s; frame "
            "interval median %.1f ms, 95th percentile %.1f ms, slowest %.1f ms); "
            "%llu renders, %llu partial frames shown\n",
            sample.name.c_str(), status.backend.c_str(), (unsigned long long)ui_frames, elapsed,
            double(ui_frames) / std::max(elapsed, 1e-9), at(0.5), at(0.95), ui_frame_ms.back(),
            (unsigned long long)shown.number, (unsigned long long)partial_uploads);
        std::printf("lucent view: panel %.0fx%.0f of a %dx%d window (ui scale %.3g)\n",
                    panel_size[0], panel_size[1], last_fb_width, last_fb_height, window.ui_scale());
        if (camera)
            std::printf("lucent view: camera %s\n", cli::camera_flags(camera->camera()).c_str());
    }
    if (soak && exit_code == 0) exit_code = soak->finish(ui_frames, shown.number);
    if (exit_code == 0 && !config.screenshot.empty())
        std::printf("wrote %s\n", config.screenshot.c_str());
    return exit_code;
}

}  // namespace lucent::viewer

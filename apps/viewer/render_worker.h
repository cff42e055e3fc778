// Renders on its own thread so the window stays responsive while a slow frame (the CPU
// backend, a full IGI render) is in progress: the window shows the last finished frame,
// and, on the CPU, the rows of the frame in progress as they finish.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "samples/sample.h"

namespace lucent::viewer {

/// A finished frame, ready to show (a display frame: 8-bit sRGB by the same encoding as
/// `lucent render`'s PNGs, left on the GPU where the CUDA backend rendered it), and what it
/// cost.
struct ShownFrame {
    uint64_t number = 0;  // 1, 2, ... in the order frames finished; 0: none yet
    unsigned width = 0, height = 0;
    std::shared_ptr<const DisplayFrame> display;
    std::vector<samples::StageTiming> stages;
    double frame_ms = 0;   // wall clock of the whole frame on the worker
    unsigned samples = 1;  // accumulated (progressive sessions)
};

/// The frame in progress on the CPU: its finished rows over the last frame, RGBA8 in host
/// memory.
struct PartialFrame {
    uint64_t number = 0;  // the frame it will become
    unsigned width = 0, height = 0;
    std::vector<unsigned char> rgba;
};

/// What the panel shows about the worker.
struct WorkerStatus {
    bool opened = false;  // the session exists (the first frame may still be rendering)
    bool busy = false;    // a frame is being rendered now
    bool progressive = false;
    std::string backend, backend_notice;
    std::string error;  // the last failure (a bad option value, an engine error)
    scene::Camera initial_camera;
    std::map<std::string, std::string> sets;  // the options in effect
    unsigned spp_limit = 0;                   // progressive: stop refining here; 0 = never
    bool denoises = false;                    // the session has the denoiser switch
    samples::ViewDenoiser denoiser = samples::ViewDenoiser::kOff;
};

class RenderWorker {
  public:
    /// Opens the sample's session on the worker thread, denoised by `denoiser` where it has
    /// the switch. `frame_limit` > 0: render frames until that many finished even when
    /// nothing changes (headless checks), then stop.
    RenderWorker(const samples::Sample& sample, samples::RenderSettings settings,
                 uint64_t frame_limit, samples::ViewDenoiser denoiser);
    ~RenderWorker();
    RenderWorker(const RenderWorker&) = delete;
    RenderWorker& operator=(const RenderWorker&) = delete;

    void set_camera(const scene::Camera& camera);
    void set_option(const std::string& name, const std::string& value);
    void reset();
    /// Progressive sessions stop refining at this many samples per pixel; 0 = never.
    void set_spp_limit(unsigned spp);
    /// The denoiser of the following frames (sessions that have one: status().denoises).
    void set_denoiser(samples::ViewDenoiser denoiser);
    /// Renders the following frames at this size (the window's, with --fit-window): the
    /// session is opened again at it, where the camera is.
    void set_size(unsigned width, unsigned height);

    /// The newest finished frame when it is newer than `after`.
    std::optional<ShownFrame> frame_after(uint64_t after);
    /// The frame in progress (its finished rows over the last frame) when it follows
    /// frame `shown` and changed since `version`, which it updates.
    std::optional<PartialFrame> partial_after(uint64_t shown, uint64_t& version);
    WorkerStatus status();
    uint64_t frames_done();

  private:
    void run();
    bool has_work() const;  // under m_mutex
    void open_session();    // on the worker thread
    /// On the worker thread, as a launch's rows finish: copies them into m_partial.
    void take_rows(const LaunchProgress& progress);

    const samples::Sample& m_sample;
    samples::RenderSettings m_settings;  // the worker thread's copy of the options in effect
    uint64_t m_frame_limit;
    std::unique_ptr<samples::InteractiveSession> m_session;

    std::mutex m_mutex;
    std::condition_variable m_wake;
    bool m_stop = false;
    std::optional<scene::Camera> m_pending_camera;
    std::map<std::string, std::string> m_pending_sets;
    bool m_pending_reset = false;
    bool m_pending_denoiser = false;
    std::optional<std::pair<unsigned, unsigned>> m_pending_size;
    bool m_converged = false;  // a still image is up to date, or the spp limit was reached
    ShownFrame m_latest;
    PartialFrame m_partial;
    uint64_t m_partial_version = 0;
    unsigned m_partial_rows = 0;  // rows of the current launch already copied
    unsigned m_partial_width = 0, m_partial_height = 0;  // the current launch's size
    WorkerStatus m_status;
    std::thread m_thread;  // last: starts after everything above exists
};

}  // namespace lucent::viewer

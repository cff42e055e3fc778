// What every sample offers the command line and the tests: a name, its options
// (given as --set name=value) and a render function.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "lucent/context.h"
#include "scene/image_io.h"
#include "scene/scene.h"

namespace lucent::samples {

/// One `--set` option of a sample.
struct SampleOption {
    std::string name;
    std::string default_value;
    std::string help;  // one line, with the accepted range
};

struct RenderSettings {
    unsigned width = 1024, height = 1024;
    BackendKind backend = BackendKind::kAuto;
    std::vector<DeviceSpec> devices;          // --devices: launches spread over these
    unsigned threads = 0;                     // CPU workers, 0 = all cores
    std::string scene;                        // built-in scene name or file; empty = default
    std::map<std::string, std::string> sets;  // --set name=value, checked by the sample
    bool verbose = false;
    int jit_check_sm = 0;  // --jit-check: also compile the CUDA megakernel
    unsigned repeat = 1;   // --repeat: launches timed after the first
    unsigned spp = 0;      // --spp: progressive samples' samples per pixel; 0 = their default
    /// Also return the sample's intermediate images (RenderResult::layers), for tests.
    bool keep_layers = false;
    /// Interactive sessions return each frame as FrameResult::display (8-bit sRGB, left
    /// on the GPU where the CUDA backend rendered it) instead of a linear host image.
    bool display_frames = false;
    /// Called as launches complete (done, total), e.g. for a progress bar; may be empty.
    std::function<void(unsigned, unsigned)> progress;
    /// Called as bands of rows of a launch finish on the CPU (ContextOptions::on_progress),
    /// e.g. for a viewer showing partial results; may be empty.
    std::function<void(const LaunchProgress&)> on_launch_progress;

    /// The Context options these settings ask for.
    ContextOptions context_options() const {
        ContextOptions options{backend, threads, jit_check_sm};
        options.devices = devices;
        options.on_progress = on_launch_progress;
        return options;
    }
};

struct StageTiming {
    std::string name;
    double ms = 0;
    std::string note;  // e.g. "median of 100 (min 0.81, max 0.95)"
};

struct RenderResult {
    scene::Image image;               // linear RGB
    std::string backend;              // Context::backend_name()
    std::string backend_notice;       // Context::backend_notice(): why auto chose the CPU
    std::vector<StageTiming> stages;  // in order: e.g. scene setup, compile, accel, launch
    LaunchReport report;              // exceptions of the last launch
    /// With RenderSettings::keep_layers: named intermediate images (e.g. IGI's "direct",
    /// "indirect", "normal"), each at the resolution it was computed at.
    std::map<std::string, scene::Image> layers;
};

/// One frame of an interactive session.
struct FrameResult {
    scene::Image image;  // linear RGB; empty with RenderSettings::display_frames
    std::shared_ptr<const DisplayFrame> display;  // with RenderSettings::display_frames
    std::vector<StageTiming> stages;  // of this frame only (a recompile shows here)
    unsigned samples = 1;             // frames accumulated into the image (progressive samples)
    LaunchReport report;              // exceptions of this frame's last launch
};

/// A sample's scene built once and rendered many times from a moving camera (`lucent view`).
/// Not thread-safe: one thread opens it and calls everything.
class InteractiveSession {
  public:
    virtual ~InteractiveSession() = default;
    /// The backend that runs it (Context::backend_name()) and why auto chose it.
    virtual std::string backend() const = 0;
    virtual std::string backend_notice() const = 0;
    /// Where the sample's own render puts the camera: the viewer starts there.
    virtual scene::Camera initial_camera() const = 0;
    /// Moves the camera; a progressive session restarts its accumulation.
    virtual void set_camera(const scene::Camera& camera) = 0;
    /// Changes a --set option in place and returns true; false when the option needs the
    /// scene rebuilt (the caller opens a new session). A bad value throws SettingsError.
    virtual bool set_option(const std::string& name, const std::string& value) = 0;
    /// Progressive sessions: drop the accumulated frames.
    virtual void reset() {}
    /// True when frame() refines the image further while nothing changes.
    virtual bool progressive() const { return false; }
    /// True when set_camera is ignored: the session renders from the sample's own camera.
    virtual bool fixed_camera() const { return false; }
    /// Renders one frame (a progressive session: one more sample per pixel).
    virtual FrameResult frame() = 0;
};

struct SampleInfo {
    std::string name;
    std::string description;
    std::vector<SampleOption> options;
    RenderResult (*render)(const RenderSettings& settings);
    /// Opens an interactive session (size, backend and --set from the settings); null for
    /// samples that have none (`lucent view` then shows their own camera's render).
    std::unique_ptr<InteractiveSession> (*open)(const RenderSettings& settings) = nullptr;
};

/// Launches `entry` over width x height, then `settings.repeat - 1` more times when asked,
/// and fills `result`: report of the first launch, stages "compile + accel", "megakernel
/// JIT" (when it ran) and "launch" (the first, or the median of the repeats with spread).
void timed_launch(Context& ctx, unsigned entry, const RenderSettings& settings,
                  RenderResult& result);

/// The sample's own session (SampleInfo::open) or, for samples without one, a session that
/// re-renders through SampleInfo::render when an option changes, from the sample's own
/// camera (fixed_camera() is true).
std::unique_ptr<InteractiveSession> open_session(const SampleInfo& info,
                                                 const RenderSettings& settings);

/// The [lo, hi] range an option's help text names, "(1..256)" or "(0..2^30)"; false when it
/// names none. For the viewer's sliders.
bool option_range(const SampleOption& option, double& lo, double& hi);

/// A viewer frame's stages from its launch report: "compile + accel" and "megakernel JIT"
/// when that launch recompiled, then "launch".
void add_launch_stages(const LaunchReport& report, std::vector<StageTiming>& stages);

/// The frame's pixels from a session's 2D float4 output: `out.display` made where the
/// launch left them (`display_frame`: RenderSettings::display_frames), else `out.image` on
/// the host. The display frame's encoding shows as the stage "display frame".
void take_frame_pixels(Context& ctx, const Buffer& output, bool display_frame, FrameResult& out);

/// Appends the stages a launch that compiled the scene reports: "compile + accel", and
/// "megakernel JIT" (cold compile or cache load) when the CUDA backend ran it.
void add_compile_stages(const LaunchReport& report, std::vector<StageTiming>& stages);

/// Every sample, in the order `--help` lists them.
const std::vector<SampleInfo>& all_samples();
/// The sample with this name, or an Error listing the names.
const SampleInfo& find_sample(const std::string& name);

/// Reads a --set value: the option's default when not given; Error naming the option,
/// the value and the accepted range when it does not parse or is out of [lo, hi].
float get_float_option(const RenderSettings& s, const SampleInfo& info, const std::string& name,
                       float lo, float hi);
int get_int_option(const RenderSettings& s, const SampleInfo& info, const std::string& name, int lo,
                   int hi);
/// Reads a --set value as text (a file name, say): the option's default when not given.
std::string get_string_option(const RenderSettings& s, const SampleInfo& info,
                              const std::string& name);
/// Error naming any --set that the sample does not have, with the list it does have.
void check_options(const RenderSettings& s, const SampleInfo& info);

}  // namespace lucent::samples

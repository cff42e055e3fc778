// What every sample offers the command line, the viewer and the tests: the Sample class (a
// name, typed options, render and open), the settings of a render and its results.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lucent/context.h"
#include "samples/aov.h"
#include "samples/camera_override.h"
#include "samples/options.h"
#include "scene/exr_encoder.h"
#include "scene/image_io.h"
#include "scene/scene.h"

namespace lucent::samples {

struct RenderSettings {
    unsigned width = 1024, height = 1024;
    BackendKind backend = BackendKind::kAuto;
    std::vector<DeviceSpec> devices;          // --devices: launches spread over these
    unsigned threads = 0;                     // CPU workers, 0 = all cores
    std::string scene;                        // built-in scene name or file; empty = default
    std::optional<unsigned> scene_camera;     // --camera N: the file's camera N (glTF)
    CameraOverride camera;                    // --eye --look --up --fov: over the scene's
    std::map<std::string, std::string> sets;  // --set name=value, checked by the sample
    bool verbose = false;
    int jit_check_sm = 0;  // --jit-check: also compile the CUDA megakernel
    unsigned repeat = 1;   // --repeat: launches timed after the first
    unsigned spp = 0;      // --spp: progressive samples' samples per pixel; 0 = their default
    /// --aov: G-buffer layers returned as RenderResult::aovs (samples with writes_aovs()).
    AovSelection aovs;
    /// Coverage ("A": 1 where the pixel's primary ray hit, 0 background) in RenderResult::aovs;
    /// `lucent render` asks for it with an .exr output.
    bool alpha = false;
    /// --denoise: the image filtered by the edge-avoiding à-trous denoiser.
    bool denoise = false;
    DenoiseOptions denoise_options;
    /// Whether any of the three needs the G-buffer pass.
    bool wants_gbuffer() const { return aovs.any() || alpha || denoise; }
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
    /// The processes each launch is spread over (`mpirun`; docs/distributed.md); null: this
    /// process alone.
    std::shared_ptr<Ranks> ranks;
    /// Called as a large scene file is read (scene::LoadProgress), e.g. for a progress bar;
    /// may be empty.
    scene::LoadProgress on_load_progress;

    /// The image's width / height, for the pinhole camera.
    float aspect() const { return float(width) / float(height); }

    /// The Context options these settings ask for.
    ContextOptions context_options() const {
        ContextOptions options{backend, threads, jit_check_sm};
        options.devices = devices;
        options.ranks = ranks;
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
    /// RenderSettings::aovs and alpha: the G-buffer's layers, named as EXR channels.
    std::vector<scene::ExrChannel> aovs;
    /// The camera the image was rendered from (the scene's with the settings' overrides),
    /// for the EXR header; samples that know it set it.
    std::optional<scene::Camera> camera;
};

/// One frame of an interactive session.
struct FrameResult {
    scene::Image image;  // linear RGB; empty with RenderSettings::display_frames
    std::shared_ptr<const DisplayFrame> display;  // with RenderSettings::display_frames
    std::vector<StageTiming> stages;  // of this frame only (a recompile shows here)
    unsigned samples = 1;             // frames accumulated into the image (progressive samples)
    LaunchReport report;              // exceptions of this frame's last launch
};

/// The viewer's denoiser switch: none, the à-trous filter on the progressive image, or its
/// temporal variant (SVGF), which keeps a history across camera moves.
enum class ViewDenoiser { kOff, kAtrous, kSvgf };
/// "off", "a-trous", "svgf": what the panel and the messages call them.
const char* view_denoiser_name(ViewDenoiser denoiser);
/// The switch's next position: off, a-trous, svgf, then off again.
ViewDenoiser next_view_denoiser(ViewDenoiser denoiser);

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
    /// True when set_denoiser() takes effect (the sample has a G-buffer pass).
    virtual bool denoises() const { return false; }
    /// Denoises the following frames so; the first switch on builds the passes (and the
    /// next frame recompiles).
    virtual void set_denoiser(ViewDenoiser) {}
    /// Renders one frame (a progressive session: one more sample per pixel).
    virtual FrameResult frame() = 0;
};

/// A sample: a renderer and its scene, with typed options. One class per sample, in the
/// sample's own folder, registered by a RegisterSample in its .cpp (no central list): it
/// builds its scene into a Context, renders one image (`lucent render`, the tests) and opens
/// an interactive session (`lucent view`), both from the same scene build and the same
/// ray-generation program, whose camera is data in a buffer.
class Sample {
  public:
    Sample(std::string name, std::string description, std::vector<SampleOption> options)
        : name(std::move(name)), description(std::move(description)), options(std::move(options)) {}
    virtual ~Sample() = default;
    Sample(const Sample&) = delete;
    Sample& operator=(const Sample&) = delete;

    const std::string name;
    const std::string description;  // one paragraph, for --help
    const std::vector<SampleOption> options;

    /// The settings' --set values checked against the options; SettingsError on bad input.
    OptionValues read_options(const RenderSettings& settings) const {
        return OptionValues(name, options, settings.sets);
    }
    /// True when render() honours RenderSettings::aovs, alpha and denoise (it launches the
    /// shared G-buffer pass, samples/aov_passes.h).
    virtual bool writes_aovs() const { return false; }
    /// Renders one image with these settings.
    virtual RenderResult render(const RenderSettings& settings) const = 0;
    /// Opens an interactive session (size, backend and --set from the settings): the same
    /// scene and ray-generation program as render(), its first frame from the sample's own
    /// camera.
    virtual std::unique_ptr<InteractiveSession> open(const RenderSettings& settings) const = 0;
};

/// Adds a sample to all_samples(): a static RegisterSample<MySample> in the sample's own
/// .cpp. `help_order` places it in --help, lowest first (names break ties), so the order
/// does not depend on the order of static initialisation.
void register_sample(std::unique_ptr<Sample> sample, int help_order);
template <class S>
struct RegisterSample {
    explicit RegisterSample(int help_order) { register_sample(std::make_unique<S>(), help_order); }
};

/// Every sample, in the order `--help` lists them.
const std::vector<const Sample*>& all_samples();
/// The sample with this name, or a SettingsError listing the names.
const Sample& find_sample(const std::string& name);
/// SettingsError when `settings` ask for AOVs or the denoiser (not for alpha alone, which a
/// sample without a G-buffer simply does not write) and `sample` has no G-buffer pass;
/// the message names the samples that have one.
void check_aov_support(const Sample& sample, const RenderSettings& settings);

}  // namespace lucent::samples

// What every sample offers the command line and the tests: a name, its options
// (given as --set name=value) and a render function.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "lucent/context.h"
#include "scene/image_io.h"

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
    unsigned threads = 0;                     // CPU workers, 0 = all cores
    std::string scene;                        // built-in scene name or file; empty = default
    std::map<std::string, std::string> sets;  // --set name=value, checked by the sample
    bool verbose = false;
    int jit_check_sm = 0;  // --jit-check: also compile the CUDA megakernel
    unsigned repeat = 1;   // --repeat: launches timed after the first
    unsigned spp = 0;      // --spp: progressive samples' samples per pixel; 0 = their default
    /// Also return the sample's intermediate images (RenderResult::layers), for tests.
    bool keep_layers = false;
    /// Called as launches complete (done, total), e.g. for a progress bar; may be empty.
    std::function<void(unsigned, unsigned)> progress;

    /// The Context options these settings ask for.
    ContextOptions context_options() const {
        return ContextOptions{backend, threads, jit_check_sm};
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

struct SampleInfo {
    std::string name;
    std::string description;
    std::vector<SampleOption> options;
    RenderResult (*render)(const RenderSettings& settings);
};

/// Launches `entry` over width x height, then `settings.repeat - 1` more times when asked,
/// and fills `result`: report of the first launch, stages "compile + accel", "megakernel
/// JIT" (when it ran) and "launch" (the first, or the median of the repeats with spread).
void timed_launch(Context& ctx, unsigned entry, const RenderSettings& settings,
                  RenderResult& result);

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

// What a render may write beside its colour (`--aov`, `--denoise`): the G-buffer layers by
// name, checked once for the command line, Python and C++ callers alike, and the denoiser's
// parameters. The passes that produce them are samples/gbuffer.h and samples/atrous_denoiser.h.
#pragma once

#include <string>
#include <vector>

namespace lucent::samples {

/// The AOV layers a render returns (RenderResult::aovs). EXR channel names follow pbrt-v4's
/// GBufferFilm where it has the layer ("Albedo.R/G/B", "Nx/Ny/Nz", "Px/Py/Pz"), OpenEXR's
/// standard "Z" for depth and "A" for coverage; docs/cli.md lists them.
struct AovSelection {
    bool albedo = false, normal = false, depth = false, position = false, instance = false;
    bool any() const { return albedo || normal || depth || position || instance; }
};

/// The accepted names, in the order --help lists them.
const std::vector<std::string>& aov_names();

/// "albedo,normal,depth" → the selection. A bad or empty name throws SettingsError naming
/// `flag`, the value and the accepted names: "--aov 'albdo': unknown AOV 'albdo' (did you
/// mean 'albedo'?); accepted: albedo, normal, depth, position, instance".
AovSelection parse_aovs(const std::string& flag, const std::string& text);
/// The same from a list of names (Python's aovs=[...]).
AovSelection parse_aovs(const std::string& flag, const std::vector<std::string>& names);

/// The edge-avoiding à-trous filter's parameters (samples/common/atrous_programs.h). The
/// defaults were chosen on the 4-spp Cornell box against 1024 spp (docs/samples.md has the
/// figures): 3 passes, not the paper's 5, because the passes with taps 8 and 16 pixels apart
/// leave broad low-frequency errors (relative MSE 0.0031 -> 0.0094 and FLIP 0.066 -> 0.136
/// at 256x256).
struct DenoiseOptions {
    unsigned iterations = 3;      // passes; the taps of pass i are 2^i pixels apart
    float sigma_colour = 8.0f;    // sigma_rt, in units of the mean illumination squared
    float sigma_normal = 0.1f;    // sigma_n of the paper's shader
    float sigma_position = 1.0f;  // sigma_x, in pixel footprints squared
    bool demodulate = true;       // filter colour / albedo, then multiply back
};

}  // namespace lucent::samples

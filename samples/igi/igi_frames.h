// A frame of the IGI sample: the images its passes hand each other (IGI paper, Fig. 3) and the
// passes launched in order, each timed, as the paper's Fig. 4 and 5 report them.
#pragma once

#include <array>
#include <memory>

#include "lucent/context.h"
#include "samples/sample.h"

namespace lucent::samples {

struct IgiConfig {
    unsigned width = 0, height = 0;
    unsigned paths = 180, bounces = 1;
    unsigned downsample = 1;  // indirect light at 1/downsample of the resolution
    unsigned interleave = 1;  // interleave x interleave VPL subsets
    unsigned layers = 1;      // G-buffer layers: 1, or 2 with the reflection layer
    unsigned slices = 1;      // each pixel's VPLs split over this many threads (indirect pass)
    unsigned visibility_map = 0;  // > 0: each VPL's visibility map is this many texels square

    unsigned low_width() const { return (width + downsample - 1) / downsample; }
    unsigned low_height() const { return (height + downsample - 1) / downsample; }
};

/// The buffers of Fig. 3. `indirect` and `merged` are at 1/downsample resolution; the rest
/// at full resolution. The G-buffer's and the indirect passes' images have `layers` layers
/// (depth); `direct` and `output` one. Buffers of passes a configuration skips are still
/// made (and small enough not to matter), so every entry point's variables are bound.
struct IgiImages {
    std::shared_ptr<Buffer> direct, gbuffer_position, gbuffer_normal, gbuffer_albedo;
    std::shared_ptr<Buffer> indirect, merged, upsampled, output;
    std::shared_ptr<Buffer> indirect_slices;  // layers x slices deep, when slices > 1

    /// The irradiance composition reads: upsampled, else merged, else as computed.
    std::shared_ptr<Buffer> irradiance_at_full_resolution(const IgiConfig& config) const;
};

/// Makes the buffers and binds the ones several passes share as context variables.
IgiImages create_igi_images(Context& ctx, const IgiConfig& config);

/// How many threads share a pixel's VPLs in the indirect pass: enough that the pass has
/// about kIndirectWorkItems of work, at most one per VPL of an interleaved subset. A
/// low-resolution image alone leaves a GPU mostly idle: at 1/16 of 800x600 (IGI paper §4.2) the
/// pass has 60,000 pixels of its two layers, and ncu saw 9 % achieved occupancy with 7 of 32
/// lanes active. Sponza, all three accelerations, H200: 1, 2, 4, 8, 16 slices took 1.47,
/// 0.88, 0.76, 0.68, 0.63 ms. The same on every backend, so images do not depend on it.
inline constexpr unsigned kIndirectWorkItems = 1u << 20;
unsigned auto_indirect_slices(const IgiConfig& config);

/// The stages of a frame in launch order; the names RenderResult::stages uses.
inline constexpr std::array<const char*, 6> kIgiStageNames = {
    "VPL generation",       "direct + specular", "indirect",
    "discontinuity filter", "upsampling",        "composition"};

/// Renders settings.repeat frames (at least one), each: VPL generation (and the VPLs'
/// visibility maps when config.visibility_map > 0), direct + specular,
/// indirect (and the sum of its slices), the discontinuity filter (interleave > 1), upsampling (downsample > 1),
/// composition. Appends to result.stages: compile + accel, megakernel JIT (when it ran),
/// each stage (the median over the frames after the first when there are several, with its
/// share of the frame), and "frame" with frames/s.
void render_igi_frames(Context& ctx, const IgiConfig& config, const RenderSettings& settings,
                       RenderResult& result);

}  // namespace lucent::samples

// A frame of the IGI sample: the images its passes hand each other (seed Fig. 3) and the
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

    unsigned low_width() const { return (width + downsample - 1) / downsample; }
    unsigned low_height() const { return (height + downsample - 1) / downsample; }
};

/// The buffers of Fig. 3. `indirect` and `merged` are at 1/downsample resolution; the rest
/// at full resolution. Buffers of passes a configuration skips are still made (and small
/// enough not to matter), so every entry point's variables are bound.
struct IgiImages {
    std::shared_ptr<Buffer> direct, gbuffer_position, gbuffer_normal, gbuffer_albedo;
    std::shared_ptr<Buffer> indirect, merged, upsampled, output;

    /// The irradiance composition reads: upsampled, else merged, else as computed.
    std::shared_ptr<Buffer> irradiance_at_full_resolution(const IgiConfig& config) const;
};

/// Makes the buffers and binds the ones several passes share as context variables.
IgiImages create_igi_images(Context& ctx, const IgiConfig& config);

/// The stages of a frame in launch order; the names RenderResult::stages uses.
inline constexpr std::array<const char*, 6> kIgiStageNames = {
    "VPL generation",       "direct + specular", "indirect",
    "discontinuity filter", "upsampling",        "composition"};

/// Renders settings.repeat frames (at least one), each: VPL generation, direct + specular,
/// indirect, the discontinuity filter (interleave > 1), upsampling (downsample > 1),
/// composition. Appends to result.stages: compile + accel, megakernel JIT (when it ran),
/// each stage (the median over the frames after the first when there are several, with its
/// share of the frame), and "frame" with frames/s.
void render_igi_frames(Context& ctx, const IgiConfig& config, const RenderSettings& settings,
                       RenderResult& result);

}  // namespace lucent::samples

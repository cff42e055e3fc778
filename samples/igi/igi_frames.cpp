// The passes of an IGI frame, launched in order and timed one by one.
#include "samples/igi/igi_frames.h"

#include <algorithm>
#include <cstdio>
#include <vector>

#include "samples/igi/igi_programs.h"
#include "samples/stages.h"

namespace lucent::samples {

std::shared_ptr<Buffer> IgiImages::irradiance_at_full_resolution(const IgiConfig& config) const {
    if (config.downsample > 1) return upsampled;
    return config.interleave > 1 ? merged : indirect;
}

unsigned auto_indirect_slices(const IgiConfig& config) {
    const unsigned long long pixels =
        1ull * config.low_width() * config.low_height() * config.layers;
    const unsigned per_subset = std::max(
        1u, (config.paths * config.bounces + config.interleave * config.interleave - 1) /
                (config.interleave * config.interleave));
    const unsigned long long wanted = (kIndirectWorkItems + pixels - 1) / pixels;
    return unsigned(std::clamp<unsigned long long>(wanted, 1, per_subset));
}

IgiImages create_igi_images(Context& ctx, const IgiConfig& config) {
    const unsigned w = config.width, h = config.height;
    const unsigned lw = config.low_width(), lh = config.low_height();
    // layers = 0: a 2D image.
    auto image = [&ctx](unsigned width, unsigned height, unsigned layers = 0,
                        BufferType type = BufferType::kInputOutput) {
        return ctx.create_buffer<float4>(type, width, height, layers);
    };
    const unsigned layers = config.layers;
    IgiImages images;
    images.direct = image(w, h);
    images.gbuffer_position = image(w, h, layers);
    images.gbuffer_normal = image(w, h, layers);
    images.gbuffer_albedo = image(w, h, layers);
    images.indirect = image(lw, lh, layers);
    images.indirect_slices = image(config.slices > 1 ? lw : 1, config.slices > 1 ? lh : 1,
                                   config.slices > 1 ? layers * config.slices : 1);
    images.merged = config.interleave > 1 ? image(lw, lh, layers) : image(1, 1, layers);
    images.upsampled = config.downsample > 1 ? image(w, h, layers) : image(1, 1, layers);
    images.output = image(w, h, 0, BufferType::kOutput);
    ctx["direct"] = images.direct;
    ctx["gbuffer_position"] = images.gbuffer_position;
    ctx["gbuffer_normal"] = images.gbuffer_normal;
    ctx["gbuffer_albedo"] = images.gbuffer_albedo;
    return images;
}

namespace {

/// Adds the exceptions of `from` to `into`.
void add_exceptions(LaunchReport& into, const LaunchReport& from) {
    for (const auto& [code, summary] : from.exceptions) {
        auto& total = into.exceptions[code];
        if (total.count == 0) total.first_index = summary.first_index;
        total.count += summary.count;
    }
}

/// One frame's launches; fills ms[stage] (0 for a skipped stage). Returns the first launch's
/// report (it compiles the scene and JITs the megakernel) with every launch's exceptions.
LaunchReport launch_frame(Context& ctx, const IgiConfig& config,
                          std::array<double, kIgiStageNames.size()>& ms) {
    ms.fill(0.0);
    LaunchReport frame;
    auto run = [&](unsigned stage, unsigned entry, unsigned width, unsigned height,
                   unsigned layers = 1) {
        ctx.launch(entry, width, height, layers);
        const LaunchReport& report = ctx.last_launch();
        if (stage == 0) {
            frame = report;
            frame.exceptions.clear();
        }
        add_exceptions(frame, report);
        ms[stage] += report.launch_ms;
    };
    run(0, igi::kVplEntry, config.paths, 1);
    // The maps are part of the VPLs: made once per frame, as they are.
    if (config.visibility_map > 0)
        run(0, igi::kVplMapEntry, config.visibility_map, config.visibility_map,
            config.paths * config.bounces);
    run(1, igi::kDirectEntry, config.width, config.height);
    run(2, igi::kIndirectEntry, config.low_width(), config.low_height(),
        config.layers * config.slices);
    if (config.slices > 1)
        run(2, igi::kIndirectSumEntry, config.low_width(), config.low_height(), config.layers);
    if (config.interleave > 1)
        run(3, igi::kDiscontinuityEntry, config.low_width(), config.low_height(), config.layers);
    if (config.downsample > 1)
        run(4, igi::kUpsampleEntry, config.width, config.height, config.layers);
    run(5, igi::kComposeEntry, config.width, config.height);
    return frame;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

}  // namespace

void render_igi_frames(Context& ctx, const IgiConfig& config, const RenderSettings& settings,
                       RenderResult& result) {
    constexpr size_t kStages = kIgiStageNames.size();
    std::array<double, kStages> ms{};
    const LaunchReport first = launch_frame(ctx, config, ms);
    add_compile_stages(first, result.stages);
    const unsigned frames = std::max(1u, settings.repeat);
    if (settings.progress) settings.progress(1, frames);
    // Per stage, its times over the frames after the first (or the first, if alone).
    std::array<std::vector<double>, kStages> times;
    std::vector<double> totals;
    auto record = [&] {
        double total = 0;
        for (size_t s = 0; s < kStages; ++s) {
            times[s].push_back(ms[s]);
            total += ms[s];
        }
        totals.push_back(total);
    };
    if (frames == 1) record();
    LaunchReport last = first;
    for (unsigned f = 1; f < frames; ++f) {
        last = launch_frame(ctx, config, ms);
        record();
        if (settings.progress) settings.progress(f + 1, frames);
    }
    result.report = first;
    result.report.exceptions.clear();
    add_exceptions(result.report, last);
    const double frame_ms = median(totals);
    const char* of = totals.size() > 1 ? "median" : "one frame";
    // Shares of the sum of the stage medians, so that they add up to 100%.
    std::array<double, kStages> stage_ms{};
    double stage_sum = 0;
    for (size_t s = 0; s < kStages; ++s) stage_sum += stage_ms[s] = median(times[s]);
    for (size_t s = 0; s < kStages; ++s) {
        if (s == 3 && config.interleave == 1) continue;
        if (s == 4 && config.downsample == 1) continue;
        char note[120];
        std::snprintf(note, sizeof note, "%.1f%% of the frame (%s)",
                      100.0 * stage_ms[s] / stage_sum, of);
        result.stages.push_back({kIgiStageNames[s], stage_ms[s], note});
    }
    char note[160];
    std::snprintf(note, sizeof note, "%.1f frames/s (%s of %zu; min %.3f, max %.3f)",
                  1000.0 / frame_ms, of, totals.size(),
                  *std::min_element(totals.begin(), totals.end()),
                  *std::max_element(totals.begin(), totals.end()));
    result.stages.push_back({"frame", frame_ms, note});
}

}  // namespace lucent::samples

// The IGI experiment of seed §5: four cumulative configurations x the VPL counts, each run for
// a number of frames through the sample itself, reporting its median frame and stage times.
#include "samples/igi/igi_bench.h"

#include <cstdio>
#include <map>
#include <string>

#include "samples/sample.h"
#include "samples/igi/igi_frames.h"

namespace lucent::samples {

namespace {

struct Configuration {
    const char* name;
    bool imperfect, downsample, interleave;
};

// Cumulative, as the paper adds them (Fig. 5): each row keeps the accelerations above it.
constexpr Configuration kConfigurations[] = {
    {"canonical", false, false, false},
    {"+imperfect visibility", true, false, false},
    {"+downsampling", true, true, false},
    {"+interleaving", true, true, true},
};

struct Row {
    std::string configuration;
    unsigned vpls = 0;
    double frame_ms = 0;
    std::map<std::string, double> stage_ms;  // by kIgiStageNames; skipped stages absent
    std::string backend;
};

Row run_one(const IgiBenchOptions& options, const Configuration& c, unsigned vpls) {
    RenderSettings settings;
    settings.width = options.width;
    settings.height = options.height;
    settings.backend = options.backend;
    settings.devices = options.devices;
    settings.threads = options.threads;
    settings.scene = options.scene;
    settings.repeat = options.frames + 1;  // the first frame compiles: not timed
    settings.sets = {
        {"vpls", std::to_string(vpls)},
        {"imperfect_visibility", c.imperfect ? "1" : "0"},
        {"downsample", c.downsample ? std::to_string(options.downsample) : "1"},
        {"interleave", c.interleave ? std::to_string(options.interleave) : "1"},
        {"reflection_layer", options.reflection_layer ? "1" : "0"},
    };
    const RenderResult result = find_sample("igi").render(settings);
    Row row{c.name, vpls, 0, {}, result.backend};
    for (const StageTiming& stage : result.stages) {
        if (stage.name == "frame") row.frame_ms = stage.ms;
        for (const char* name : kIgiStageNames)
            if (stage.name == name) row.stage_ms[name] = stage.ms;
    }
    return row;
}

void print_json(const IgiBenchOptions& options, const std::vector<Row>& rows) {
    std::printf(
        "{\"benchmark\": \"igi\", \"scene\": \"%s\", \"backend\": \"%s\", \"width\": %u, "
        "\"height\": %u, \"frames\": %u, \"reflection_layer\": %s, \"rows\": [",
        options.scene.c_str(), rows.empty() ? "" : rows[0].backend.c_str(), options.width,
        options.height, options.frames, options.reflection_layer ? "true" : "false");
    for (size_t i = 0; i < rows.size(); ++i) {
        const Row& r = rows[i];
        std::printf(
            "%s\n  {\"configuration\": \"%s\", \"vpls\": %u, \"frame_ms\": %.4f, "
            "\"fps\": %.2f, \"stage_ms\": {",
            i ? "," : "", r.configuration.c_str(), r.vpls, r.frame_ms, 1000.0 / r.frame_ms);
        bool first = true;
        for (const char* name : kIgiStageNames) {
            auto it = r.stage_ms.find(name);
            if (it == r.stage_ms.end()) continue;
            std::printf("%s\"%s\": %.4f", first ? "" : ", ", name, it->second);
            first = false;
        }
        std::printf("}}");
    }
    std::printf("\n]}\n");
}

void print_table(const IgiBenchOptions& options, const std::vector<Row>& rows) {
    std::printf(
        "igi: %s, %ux%u on %s, median of %u frames, reflection layer %s; stage shares in %% of "
        "the frame\n",
        options.scene.c_str(), options.width, options.height,
        rows.empty() ? "?" : rows[0].backend.c_str(), options.frames,
        options.reflection_layer ? "on" : "off (inline, as in the paper)");
    std::printf("%-22s %5s %9s %9s %7s %7s %8s %7s %7s %7s\n", "configuration", "VPLs", "frames/s",
                "frame ms", "VPLgen", "direct", "indirect", "discont", "upsamp", "compose");
    for (const Row& r : rows) {
        std::printf("%-22s %5u %9.2f %9.3f", r.configuration.c_str(), r.vpls, 1000.0 / r.frame_ms,
                    r.frame_ms);
        double stage_sum = 0;  // of the stage medians: the shares add up to 100%
        for (const auto& [name, ms] : r.stage_ms) stage_sum += ms;
        for (const char* name : kIgiStageNames) {
            auto it = r.stage_ms.find(name);
            if (it == r.stage_ms.end())
                std::printf(" %7s", "-");
            else
                std::printf(" %6.1f%%", 100.0 * it->second / stage_sum);
        }
        std::printf("\n");
    }
}

}  // namespace

int run_igi_bench(const IgiBenchOptions& options) {
    std::vector<Row> rows;
    const unsigned total = unsigned(std::size(kConfigurations) * options.vpls.size());
    for (const Configuration& c : kConfigurations)
        for (unsigned vpls : options.vpls) {
            rows.push_back(run_one(options, c, vpls));
            if (options.progress) options.progress(unsigned(rows.size()), total);
        }
    if (options.json)
        print_json(options, rows);
    else
        print_table(options, rows);
    return 0;
}

}  // namespace lucent::samples

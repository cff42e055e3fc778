// The IGI experiment of Marques and Santos: four cumulative configurations x the VPL counts,
// each run for a number of frames through the sample itself, reporting its median frame and
// stage times.
#include "bench/igi/igi_bench.h"

#include <cstdio>
#include <map>
#include <string>
#include <utility>

#include "bench/common/option_checks.h"
#include "bench/common/report.h"
#include "lucent/error.h"
#include "samples/sample.h"
#include "samples/igi/igi_frames.h"

namespace lucent::bench {

using samples::find_sample;
using samples::kIgiStageNames;
using samples::RenderResult;
using samples::RenderSettings;
using samples::StageTiming;

namespace {

struct Configuration {
    const char* name;
    unsigned imperfect;  // the sample's imperfect_visibility: 0 exact, 1 leaf boxes, 2 box
                         // graph, 3 visibility maps
    bool downsample, interleave;
};

// Cumulative, as the paper adds them (Fig. 5): each row keeps the accelerations above it.
// The paper's own form of imperfect visibility, a second graph of triangle boxes, and the
// visibility maps of its reference [3] are the rows after canonical, beside the leaf boxes
// that the cumulative rows use.
constexpr Configuration kConfigurations[] = {
    {"canonical", 0, false, false},
    {"imperfect, box graph", 2, false, false},
    {"imperfect, maps", 3, false, false},
    {"+imperfect visibility", 1, false, false},
    {"+downsampling", 1, true, false},
    {"+interleaving", 1, true, true},
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
    settings.ranks = options.ranks;
    settings.scene = options.scene;
    settings.repeat = options.frames + 1;  // the first frame compiles: not timed
    settings.sets = {
        {"vpls", std::to_string(vpls)},
        {"imperfect_visibility", std::to_string(c.imperfect)},
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

/// What `lucent bench igi` measured: a row per configuration and VPL count.
struct IgiResult {
    const IgiBenchOptions* options = nullptr;
    std::vector<Row> rows;
};

Json to_json(const IgiResult& result) {
    const IgiBenchOptions& options = *result.options;
    const std::vector<Row>& rows = result.rows;
    Json list = Json::array();
    for (const Row& r : rows) {
        Json stages = Json::object();
        for (const char* name : kIgiStageNames) {
            auto it = r.stage_ms.find(name);
            if (it != r.stage_ms.end()) stages[name] = rounded(it->second, 4);
        }
        list.push_back(Json{{"configuration", r.configuration},
                            {"vpls", r.vpls},
                            {"frame_ms", rounded(r.frame_ms, 4)},
                            {"fps", rounded(1000.0 / r.frame_ms, 2)},
                            {"stage_ms", stages}});
    }
    return Json{{"benchmark", "igi"},
                {"scene", options.scene},
                {"backend", rows.empty() ? "" : rows[0].backend},
                {"width", options.width},
                {"height", options.height},
                {"frames", options.frames},
                {"reflection_layer", options.reflection_layer},
                {"rows", list}};
}

void print_text(const IgiResult& result) {
    const IgiBenchOptions& options = *result.options;
    const std::vector<Row>& rows = result.rows;
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

void check_options(const IgiBenchOptions& options) {
    if (options.scene.empty())
        throw Error("bench igi: no scene (scene, --scene); give a built-in scene's name "
                    "(cornell) or a scene file");
    require_in_range("bench igi", "frames (--frames)", options.frames, 1, 100000);
    if (options.vpls.empty())
        throw Error("bench igi: vpls (--vpls) is empty; give at least one VPL count, e.g. 30");
    for (const unsigned vpls : options.vpls)
        require_in_range("bench igi", "a VPL count (vpls, --vpls)", vpls, 1, 65536);
    require_in_range("bench igi", "downsample (--downsample)", options.downsample, 2, 16);
    require_in_range("bench igi", "interleave (--interleave)", options.interleave, 2, 8);
    require_in_range("bench igi", "threads (--threads)", options.threads, 0, 4096);
    require_image_size("bench igi", options.width, options.height);
}

}  // namespace

std::string bench_igi_json(IgiBenchOptions options) {
    return captured_document("bench igi", std::move(options), run_igi_bench);
}

int run_igi_bench(const IgiBenchOptions& options) {
    check_options(options);
    IgiResult result;
    result.options = &options;
    std::vector<Row>& rows = result.rows;
    const unsigned total = unsigned(std::size(kConfigurations) * options.vpls.size());
    for (const Configuration& c : kConfigurations)
        for (unsigned vpls : options.vpls) {
            rows.push_back(run_one(options, c, vpls));
            if (options.progress) options.progress(unsigned(rows.size()), total);
        }
    report(result, options.json);
    return 0;
}

}  // namespace lucent::bench

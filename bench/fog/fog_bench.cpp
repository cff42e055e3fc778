// Sebald's Table 1 on any backend: per configuration, one warm-up frame (compile, JIT), then
// `frames` frames with the camera moving once around its orbit; frames/s is their count over
// their summed launch time, as the paper averages over a moving camera.
#include "bench/fog/fog_bench.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "bench/common/option_checks.h"
#include "bench/common/report.h"
#include "lucent/error.h"
#include "samples/fog/fog_scene.h"

namespace lucent::bench {

using samples::FogOptions;
using samples::FogScene;

namespace {

struct Row {
    std::string name;
    double fps = 0, median_ms = 0, min_ms = 0, max_ms = 0;
    std::string backend;
};

/// What `lucent bench fog` measured: a row per configuration.
struct FogResult {
    const FogBenchOptions* options = nullptr;
    std::vector<Row> rows;
};

Json to_json(const FogResult& result) {
    const FogBenchOptions& options = *result.options;
    Json rows = Json::array();
    for (const Row& r : result.rows)
        rows.push_back(Json{{"configuration", r.name},
                            {"fps", rounded(r.fps, 3)},
                            {"median_ms", rounded(r.median_ms, 4)},
                            {"min_ms", rounded(r.min_ms, 4)},
                            {"max_ms", rounded(r.max_ms, 4)}});
    return Json{{"benchmark", "fog"},       {"backend", result.rows[0].backend},
                {"width", options.width},   {"height", options.height},
                {"frames", options.frames}, {"rows", rows}};
}

void print_text(const FogResult& result) {
    const FogBenchOptions& options = *result.options;
    std::printf("fog: tutorial scene, %ux%u on %s, %u frames around the orbit per row\n",
                options.width, options.height, result.rows[0].backend.c_str(), options.frames);
    std::printf("%-16s %10s %10s %10s %10s\n", "configuration", "frames/s", "median ms", "min ms",
                "max ms");
    for (const Row& r : result.rows)
        std::printf("%-16s %10.2f %10.3f %10.3f %10.3f\n", r.name.c_str(), r.fps, r.median_ms,
                    r.min_ms, r.max_ms);
}

void check_options(const FogBenchOptions& options) {
    require_in_range("bench fog", "frames (--frames)", options.frames, 1, 100000);
    require_in_range("bench fog", "threads (--threads)", options.threads, 0, 4096);
    require_image_size("bench fog", options.width, options.height);
}

}  // namespace

std::string bench_fog_json(FogBenchOptions options) {
    return captured_document("bench fog", std::move(options), run_fog_bench);
}

int run_fog_bench(const FogBenchOptions& options) {
    check_options(options);
    struct Configuration {
        const char* name;
        bool fog;
        float step;
    };
    const Configuration configurations[] = {
        {"no fog", false, 0.1f},
        {"fog, step 0.1", true, 0.1f},
        {"fog, step 0.05", true, 0.05f},
        {"fog, step 0.01", true, 0.01f},
    };
    const unsigned total = unsigned(std::size(configurations)) * options.frames;
    FogResult result;
    result.options = &options;
    std::vector<Row>& rows = result.rows;
    unsigned done = 0;
    for (const Configuration& c : configurations) {
        FogOptions fog;
        fog.fog = c.fog;
        fog.step = c.step;
        ContextOptions context{options.backend, options.threads, 0};
        context.devices = options.devices;
        FogScene scene(fog, options.width, options.height, context);
        scene.render(0.0f);  // warm-up: compile, acceleration, JIT
        std::vector<double> ms;
        double sum = 0;
        for (unsigned f = 0; f < options.frames; ++f) {
            const double t = scene.render(360.0f * float(f) / float(options.frames)).launch_ms;
            ms.push_back(t);
            sum += t;
            if (options.progress) options.progress(++done, total);
        }
        std::sort(ms.begin(), ms.end());
        rows.push_back({c.name, 1000.0 * options.frames / sum, ms[ms.size() / 2], ms.front(),
                        ms.back(), scene.context().backend_name()});
    }
    report(result, options.json);
    return 0;
}

}  // namespace lucent::bench

// Sebald's Table 1 on any backend: per configuration, one warm-up frame (compile, JIT), then
// `frames` frames with the camera moving once around its orbit; frames/s is their count over
// their summed launch time, as the paper averages over a moving camera.
#include "samples/fog/fog_bench.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "samples/fog/fog_scene.h"

namespace lucent::samples {

namespace {

struct Row {
    std::string name;
    double fps = 0, median_ms = 0, min_ms = 0, max_ms = 0;
    std::string backend;
};

}  // namespace

int run_fog_bench(const FogBenchOptions& options) {
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
    std::vector<Row> rows;
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
    if (options.json) {
        std::printf(
            "{\"benchmark\": \"fog\", \"backend\": \"%s\", \"width\": %u, \"height\": %u, "
            "\"frames\": %u, \"rows\": [",
            rows[0].backend.c_str(), options.width, options.height, options.frames);
        for (size_t i = 0; i < rows.size(); ++i)
            std::printf(
                "%s\n  {\"configuration\": \"%s\", \"fps\": %.3f, \"median_ms\": %.4f, "
                "\"min_ms\": %.4f, \"max_ms\": %.4f}",
                i ? "," : "", rows[i].name.c_str(), rows[i].fps, rows[i].median_ms, rows[i].min_ms,
                rows[i].max_ms);
        std::printf("\n]}\n");
        return 0;
    }
    std::printf("fog: tutorial scene, %ux%u on %s, %u frames around the orbit per row\n",
                options.width, options.height, rows[0].backend.c_str(), options.frames);
    std::printf("%-16s %10s %10s %10s %10s\n", "configuration", "frames/s", "median ms", "min ms",
                "max ms");
    for (const Row& r : rows)
        std::printf("%-16s %10.2f %10.3f %10.3f %10.3f\n", r.name.c_str(), r.fps, r.median_ms,
                    r.min_ms, r.max_ms);
    return 0;
}

}  // namespace lucent::samples

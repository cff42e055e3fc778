#include "bench/present/present_bench.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "present/headless_gl.h"
#include "present/image_view.h"
#include "bench/common/report.h"
#include "samples/sample.h"

namespace lucent::bench {

using viewer::HeadlessGl;
using viewer::ImageView;
namespace {

using Clock = std::chrono::steady_clock;

double ms_between(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

struct Spread {
    double median = 0, min = 0, max = 0;
};

Spread spread_of(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return {v[v.size() / 2], v.front(), v.back()};
}

struct PathResult {
    std::string path;  // how the frames reached the texture (ImageView::presentation)
    Spread encode;     // the display frame, on the thread that renders
    Spread calls;      // show + draw as the window's thread spends them (no wait)
    Spread gpu;        // show + draw on the GPU (an OpenGL timer query)
    Spread present;    // show + draw + glFinish: the round trip
    bool shown_equals_rendered = false;
};

/// Whether the framebuffer (drawn 1:1) holds the frame's pixels: RGB, row 0 at the top.
bool framebuffer_equals(const DisplayFrame& frame) {
    const unsigned w = frame.width(), h = frame.height();
    std::vector<unsigned char> read(size_t(w) * h * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, GLsizei(w), GLsizei(h), GL_RGBA, GL_UNSIGNED_BYTE, read.data());
    const std::vector<unsigned char> rendered = frame.rgba();
    for (unsigned y = 0; y < h; ++y)
        for (unsigned x = 0; x < w; ++x)
            for (unsigned c = 0; c < 3; ++c)  // OpenGL's rows start at the bottom
                if (read[(size_t(h - 1 - y) * w + x) * 4 + c] != rendered[(size_t(y) * w + x) * 4 + c])
                    return false;
    return true;
}

/// What `lucent bench present` measured: a row per presentation path.
struct PresentResult {
    const PresentBenchOptions* options = nullptr;
    std::string sample, backend, renderer;
    std::vector<PathResult> paths;
};

Json to_json(const PresentResult& result) {
    const PresentBenchOptions& options = *result.options;
    Json paths = Json::array();
    for (const PathResult& r : result.paths)
        paths.push_back(Json{{"path", r.path},
                             {"encode_median_ms", rounded(r.encode.median, 4)},
                             {"calls_median_ms", rounded(r.calls.median, 4)},
                             {"gpu_median_ms", rounded(r.gpu.median, 4)},
                             {"gpu_min_ms", rounded(r.gpu.min, 4)},
                             {"gpu_max_ms", rounded(r.gpu.max, 4)},
                             {"round_trip_median_ms", rounded(r.present.median, 4)},
                             {"round_trip_min_ms", rounded(r.present.min, 4)},
                             {"round_trip_max_ms", rounded(r.present.max, 4)},
                             {"shown_equals_rendered", r.shown_equals_rendered}});
    return Json{{"benchmark", "present"},
                {"sample", result.sample},
                {"backend", result.backend},
                {"renderer", result.renderer},
                {"width", options.width},
                {"height", options.height},
                {"frames", options.frames},
                {"paths", paths}};
}

void print_text(const PresentResult& result) {
    const PresentBenchOptions& options = *result.options;
    const std::vector<PathResult>& results = result.paths;
    std::printf("present: %s at %ux%u on %s; OpenGL: %s; %u frames per path\n",
                result.sample.c_str(), options.width, options.height, result.backend.c_str(),
                result.renderer.c_str(), options.frames);
    std::printf("%-20s %8s %8s %26s %26s  %s\n", "path", "encode", "calls",
                "GPU (median [min, max])", "round trip (median [...])", "shown = rendered");
    for (const PathResult& r : results)
        std::printf("%-20.20s %8.3f %8.3f %8.3f [%6.3f, %7.3f] %8.3f [%6.3f, %7.3f]  %s\n",
                    r.path.c_str(), r.encode.median, r.calls.median, r.gpu.median, r.gpu.min,
                    r.gpu.max, r.present.median, r.present.min, r.present.max,
                    r.shown_equals_rendered ? "yes" : "NO");
    if (results[0].path.rfind("host upload (", 0) == 0)
        std::printf("interop: %s\n", results[0].path.c_str());
    std::printf(
        "ms per frame. encode: the display frame from the launch's output (8-bit sRGB), on "
        "the thread that renders; calls: show + draw on the window's thread, not waiting; "
        "GPU: show + draw on the GPU (OpenGL timer query); round trip: show + draw + "
        "glFinish\n");
}

double stage_ms(const samples::FrameResult& frame, const char* name) {
    for (const samples::StageTiming& s : frame.stages)
        if (s.name == name) return s.ms;
    return 0;
}

}  // namespace

int run_present_bench(const PresentBenchOptions& options) {
    const samples::Sample& info = samples::find_sample(options.sample);
    HeadlessGl gl(int(options.width), int(options.height),
                  options.backend != BackendKind::kCpu);
    samples::RenderSettings settings;
    settings.width = options.width;
    settings.height = options.height;
    settings.backend = options.backend;
    settings.threads = options.threads;
    settings.display_frames = true;
    std::unique_ptr<samples::InteractiveSession> session = info.open(settings);
    const std::string backend = session->backend();

    // The interop path first (it falls back to the host path by itself where interop does
    // not work), then the host path on purpose.
    constexpr const char* kInterop = "CUDA-OpenGL interop";
    std::vector<PathResult> results;
    unsigned total = 2 * (options.frames + 3), done = 0;
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 1 && results[0].path != kInterop) break;  // it was the host path already
        ImageView view;
        if (pass == 1) view.disable_interop("for comparison");
        GLuint timer = 0;
        glGenQueries(1, &timer);
        std::vector<double> encode, calls, gpu, present;
        bool equal = true;
        for (unsigned f = 0; f < options.frames + 3; ++f) {
            const samples::FrameResult frame = session->frame();  // not timed: the render
            glFinish();  // nothing of the last frame left in flight
            const Clock::time_point start = Clock::now();
            glBeginQuery(GL_TIME_ELAPSED, timer);
            view.show(*frame.display);
            view.draw(int(options.width), int(options.height));
            glEndQuery(GL_TIME_ELAPSED);
            const Clock::time_point issued = Clock::now();
            glFinish();  // the texture and the draw are done, as before a swap
            const Clock::time_point finished = Clock::now();
            GLuint64 gpu_ns = 0;
            glGetQueryObjectui64v(timer, GL_QUERY_RESULT, &gpu_ns);
            if (f == 0) equal = framebuffer_equals(*frame.display);
            if (f >= 3) {  // after warm-up: kernel compile, first registration, allocations
                encode.push_back(stage_ms(frame, "display frame"));
                calls.push_back(ms_between(start, issued));
                gpu.push_back(double(gpu_ns) * 1e-6);
                present.push_back(ms_between(start, finished));
            }
            if (options.progress) options.progress(++done, total);
        }
        glDeleteQueries(1, &timer);
        if (view.presentation() != kInterop) total = done;
        results.push_back({view.presentation(), spread_of(encode), spread_of(calls),
                           spread_of(gpu), spread_of(present), equal});
    }

    const bool all_equal = std::all_of(results.begin(), results.end(),
                                       [](const PathResult& r) { return r.shown_equals_rendered; });
    report(PresentResult{&options, info.name, backend, gl.renderer(), results}, options.json);
    return all_equal ? 0 : 1;
}

}  // namespace lucent::bench

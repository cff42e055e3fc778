// Measures Lucent's ray tracing against Embree on a scene of your own, from your own
// program, as `lucent bench rays --json` does: the ray sets of shared/BENCH.md (primary rays
// from the scene's camera, a shadow ray and a cosine-distributed diffuse ray from each hit)
// traced by Lucent's bare kernels, its ray streams and, with --programs, a program module
// launched through a Context; Embree traces the same rays on the same threads. Then it times
// the scene's BVH build beside Embree's, as `lucent bench build --json` does.
//
//   bench-rays [--scene FILE.obj] [--size WxH] [--repeat N] [--programs]
//              [--backend cpu|cuda] [--out FILE.json]
//
// The camera comes from cameras.txt beside the scene (room.obj, the default scene, has
// one). Prints a table of Mrays/s and ratios and a line for the build; --out writes the
// rays' whole document.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "bench/build/build_bench.h"
#include "bench/rays/rays_bench.h"
#include "lucent/error.h"

#ifndef BENCH_RAYS_DEFAULT_SCENE
#define BENCH_RAYS_DEFAULT_SCENE "room.obj"
#endif

namespace {

struct Arguments {
    lucent::bench::RaysOptions options;
    std::string out;
};

void usage() {
    std::fprintf(stderr,
                 "usage: bench-rays [--scene FILE.obj] [--size WxH] [--repeat N] [--programs] "
                 "[--backend cpu|cuda] [--out FILE.json]\n");
}

/// Parses the command line; false (after saying why) on a bad argument. The scene file and
/// its camera are checked when the benchmark reads them.
bool parse_args(int argc, char** argv, Arguments& a) {
    lucent::bench::RaysOptions& o = a.options;
    o.scene = BENCH_RAYS_DEFAULT_SCENE;
    o.width = 320, o.height = 240;
    o.repeat = 3;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--programs") {
            o.programs = true;
            continue;
        }
        const std::string value = i + 1 < argc ? argv[++i] : "";
        unsigned w = 0, h = 0;
        char end = 0;
        if (flag == "--scene" && !value.empty()) {
            o.scene = value;
        } else if (flag == "--size" && std::sscanf(value.c_str(), "%ux%u%c", &w, &h, &end) == 2 &&
                   w > 0 && h > 0 && w <= 16384 && h <= 16384) {
            o.width = w, o.height = h;
        } else if (flag == "--repeat" && std::atoi(value.c_str()) > 0) {
            o.repeat = std::atoi(value.c_str());
        } else if (flag == "--backend" && (value == "cpu" || value == "cuda")) {
            o.backend = value;
        } else if (flag == "--out" && !value.empty()) {
            a.out = value;
        } else {
            std::fprintf(stderr, "bench-rays: bad argument '%s%s%s'\n", flag.c_str(),
                         value.empty() ? "" : " ", value.c_str());
            usage();
            return false;
        }
    }
    return true;
}

/// The build's line: Lucent's tree (its SAH cost and size, which `lucent bench build` on the
/// same scene gives too) and the median build time, beside Embree's when it ran.
void print_build(const nlohmann::json& b) {
    std::printf("build    %s triangles, sah_cost %s, %s wide nodes, %.2f ms",
                b["triangles"].dump().c_str(), b["sah_cost"].dump().c_str(),
                b["wide_nodes"].dump().c_str(), b["build_ms"].get<double>());
    if (b.contains("embree_build_ms"))
        std::printf(", Embree %.2f ms, %.2fx", b["embree_build_ms"].get<double>(),
                    b["ratio"].get<double>());
    std::printf("\n");
}

/// One row: a ray kind's Mrays/s for each engine the document has, and the ratios.
void print_row(const nlohmann::json& d, const char* kind) {
    auto rate = [&](const nlohmann::json& engine) {
        return engine.contains(kind) ? engine[kind]["mrays"].get<double>() : 0.0;
    };
    std::printf("%-8s %10.2f", kind, rate(d["lucent"]));
    if (d.contains("streams")) std::printf(" %10.2f", rate(d["streams"]));
    if (d.contains("embree"))
        std::printf(" %10.2f %8.2fx", rate(d["embree"]), d["ratio"][kind].get<double>());
    if (d.contains("programs")) std::printf(" %10.2f", rate(d["programs"]));
    if (d.contains("programs_deferred")) std::printf(" %10.2f", rate(d["programs_deferred"]));
    std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
    Arguments args;
    if (!parse_args(argc, argv, args)) return 2;
    try {
        // Measured here, in this process; nothing is printed until it returns.
        const std::string text = lucent::bench::bench_rays_json(args.options);
        const nlohmann::json d = nlohmann::json::parse(text);
        std::printf("%s: %s triangles, %ux%u rays, %s threads\n", args.options.scene.c_str(),
                    d["triangles"].dump().c_str(), args.options.width, args.options.height,
                    d.contains("threads") ? d["threads"].dump().c_str() : "GPU");
        std::printf("%-8s %10s%s%s%s%s   (Mrays/s)\n", "rays", "kernels",
                    d.contains("streams") ? "    streams" : "",
                    d.contains("embree") ? "     embree    ratio" : "",
                    d.contains("programs") ? "   programs" : "",
                    d.contains("programs_deferred") ? "   deferred" : "");
        for (const char* kind : {"primary", "shadow", "diffuse"}) print_row(d, kind);
        if (d.contains("checksums_agree"))
            std::printf("checksums agree with Embree: %s\n",
                        d["checksums_agree"].get<bool>() ? "yes" : "no");
        // The CPU's build (with --backend cuda, `bench build` times the GPU builder instead;
        // its document has other keys).
        lucent::bench::BuildBenchOptions build;
        build.scene = args.options.scene;
        build.repeat = args.options.repeat;
        build.threads = args.options.threads;
        print_build(nlohmann::json::parse(lucent::bench::bench_build_json(build)));
        if (!args.out.empty()) {
            std::ofstream out(args.out, std::ios::binary);
            out << text;
            if (!out.flush()) {
                std::fprintf(stderr, "bench-rays: could not write %s\n", args.out.c_str());
                return 1;
            }
            std::printf("wrote %s\n", args.out.c_str());
        }
        return 0;
    } catch (const lucent::Error& e) {
        std::fprintf(stderr, "bench-rays: %s\n", e.what());
        return 1;
    }
}

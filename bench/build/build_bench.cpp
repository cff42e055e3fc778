// `lucent bench build`: TriangleAccel build time on an OBJ, beside Embree's on the same mesh.
#include <algorithm>
#include <cstdio>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "accel/triangle_accel.h"
#include "bench/build/build_bench.h"
#include "bench/common/bench_camera.h"
#include "bench/common/embree_peer.h"
#include "bench/common/option_checks.h"
#include "bench/common/rate.h"
#include "bench/common/report.h"
#include "lucent/error.h"
#include "scene/obj_mesh.h"
#ifdef LUCENT_HAVE_CUDA
#include "bench/build/build_bench_cuda.h"
#endif

namespace lucent::bench {

namespace {

/// Cuts every triangle into four at its edge midpoints, `levels` times (4^levels as many).
scene::ObjMesh subdivided(scene::ObjMesh mesh, unsigned levels) {
    for (unsigned level = 0; level < levels; ++level) {
        std::vector<uint3> indices;
        indices.reserve(4 * mesh.indices.size());
        for (const uint3 t : mesh.indices) {
            const float3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
            const unsigned ab = (unsigned)mesh.positions.size();
            mesh.positions.push_back(0.5f * (a + b));
            mesh.positions.push_back(0.5f * (b + c));
            mesh.positions.push_back(0.5f * (c + a));
            const unsigned bc = ab + 1, ca = ab + 2;
            indices.push_back(make_uint3(t.x, ab, ca));
            indices.push_back(make_uint3(ab, t.y, bc));
            indices.push_back(make_uint3(ca, bc, t.z));
            indices.push_back(make_uint3(ab, bc, ca));
        }
        mesh.indices = std::move(indices);
    }
    return mesh;
}

/// What `lucent bench build` measured on the CPU.
struct BuildResult {
    const BuildBenchOptions* options = nullptr;
    size_t triangles = 0;
    unsigned threads = 0;
    Rate build_ms;  // TriangleAccel's builds, in ms
    accel::BuildStats stats;
    bool peer = false;  // Embree ran
    double embree_ms = 0;
};

Json to_json(const BuildResult& r) {
    const double ms = r.build_ms.median;
    Json j{{"scene", r.options->scene},
           {"triangles", r.triangles},
           {"threads", r.threads},
           {"build_ms", rounded(ms, 3)},
           {"min_ms", rounded(r.build_ms.min, 3)},
           {"max_ms", rounded(r.build_ms.max, 3)},
           {"mtris_per_s", rounded(r.triangles / ms * 1e-3, 3)},
           {"sah_cost", rounded(r.stats.sah_cost, 4)},
           {"wide_nodes", r.stats.node_count},
           {"leaves", r.stats.leaf_count},
           {"large_leaves", r.stats.large_leaf_count},
           {"depth", r.stats.depth}};
    if (r.peer) {
        j["embree_build_ms"] = rounded(r.embree_ms, 3);
        j["ratio"] = rounded(r.embree_ms / ms, 4);
    }
    return j;
}

void print_text(const BuildResult& r) {
    const double ms = r.build_ms.median;
    std::printf("scene %s: %zu triangles, median of %d builds on %u threads\n",
                r.options->scene.c_str(), r.triangles, r.options->repeat, r.threads);
    std::printf(
        "build %.2f ms (min %.2f, max %.2f) %.2f Mtris/s sah=%.3f wide_nodes=%zu "
        "leaves=%zu large_leaves=%zu depth=%u\n",
        ms, r.build_ms.min, r.build_ms.max, r.triangles / ms * 1e-3, r.stats.sah_cost,
        r.stats.node_count, r.stats.leaf_count, r.stats.large_leaf_count, r.stats.depth);
    if (r.peer) {
        std::printf("embree build %.2f ms (RTC_BUILD_QUALITY_HIGH, %u threads)\n", r.embree_ms,
                    r.threads);
        std::printf("ratio build %.2fx (embree time / lucent time)\n", r.embree_ms / ms);
    }
}

void check_options(const BuildBenchOptions& options) {
    if (options.scene.empty())
        throw Error("bench build: no scene (scene, --scene); give an OBJ file's path");
    require_in_range("bench build", "repeat (--repeat)", options.repeat, 1, 1000);
    require_in_range("bench build", "threads (--threads)", options.threads, 0, 4096);
    // Each level makes four times the triangles: sponza at 5 has 269M.
    require_in_range("bench build", "subdivide (--subdivide)", options.subdivide, 0, 5);
    if (options.backend != "cpu" && options.backend != "cuda")
        throw Error("bench build: backend (--backend) is \"" + options.backend +
                    "\"; use \"cpu\" or \"cuda\"");
    require_image_size("bench build", options.width, options.height);
}

}  // namespace

std::string bench_build_json(BuildBenchOptions options) {
    return captured_document("bench build", std::move(options), run_bench_build);
}

int run_bench_build(const BuildBenchOptions& options) {
    check_options(options);
    const scene::ObjMesh mesh = subdivided(scene::load_obj_mesh(options.scene), options.subdivide);
    const unsigned threads =
        options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
    const size_t tris = mesh.indices.size();
    if (options.backend == "cuda") {
#ifdef LUCENT_HAVE_CUDA
        cuda::CudaBuildInput in;
        in.scene = options.scene;
        in.positions = mesh.positions;
        in.indices = mesh.indices;
        in.repeat = options.repeat;
        in.json = options.json;
        in.width = options.width, in.height = options.height;
        try {
            in.camera = find_camera(options.scene);
        } catch (const Error& e) {
            // The builds are still timed; the report says no rays were traced, and why.
            std::fprintf(stderr, "lucent bench build: no ray comparison: %s\n", e.what());
        }
        return cuda::run_bench_build_cuda(in);
#else
        throw Error(
            "--backend cuda: this lucent was built without the CUDA backend (no CUDA "
            "toolkit at configure time); run with --backend cpu");
#endif
    }

    // One warm-up build, then the timed ones.
    BuildResult result;
    result.options = &options;
    result.triangles = tris;
    result.threads = threads;
    std::vector<double> ms;
    accel::BuildOptions build_options;
    build_options.threads = threads;  // as many as Embree's build gets
    for (int run = -1; run < options.repeat; ++run) {
        accel::TriangleAccel accel;
        accel.build(mesh.positions, mesh.indices, build_options, &result.stats);
        if (run >= 0) ms.push_back(result.stats.build_ms);
    }
    result.build_ms = rate_of(ms);

    result.peer = options.peer && EmbreePeer::available();
    if (result.peer) {
        EmbreePeer e(mesh.positions, mesh.indices, threads);
        std::vector<double> ems;
        for (int run = 0; run < options.repeat; ++run) ems.push_back(e.rebuild());
        result.embree_ms = median_of(ems);
    }
    report(result, options.json);
    return 0;
}

}  // namespace lucent::bench

// `lucent bench build`: TriangleAccel build time on an OBJ, beside Embree's on the same mesh.
#include <algorithm>
#include <cstdio>
#include <thread>
#include <vector>

#include "accel/triangle_accel.h"
#include "bench/bench_camera.h"
#include "bench/bench_commands.h"
#include "bench/embree_peer.h"
#include "lucent/error.h"
#include "scene/obj_mesh.h"
#ifdef LUCENT_HAVE_CUDA
#include "bench/bench_rays_cuda.h"
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

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    size_t m = v.size();
    return m % 2 ? v[m / 2] : 0.5 * (v[m / 2 - 1] + v[m / 2]);
}

}  // namespace

int run_bench_build(const BuildBenchOptions& options) {
    if (options.repeat < 1) throw Error("bench build: --repeat must be at least 1");
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
    std::vector<double> ms;
    accel::BuildStats stats;
    for (int run = -1; run < options.repeat; ++run) {
        accel::TriangleAccel accel;
        accel.build(mesh.positions, mesh.indices, {}, &stats);
        if (run >= 0) ms.push_back(stats.build_ms);
    }
    const double lucent_ms = median(ms);
    const double lo = *std::min_element(ms.begin(), ms.end());
    const double hi = *std::max_element(ms.begin(), ms.end());

    const bool peer = options.peer && EmbreePeer::available();
    double embree_ms = 0;
    if (peer) {
        EmbreePeer e(mesh.positions, mesh.indices, threads);
        std::vector<double> ems;
        for (int run = 0; run < options.repeat; ++run) ems.push_back(e.rebuild());
        embree_ms = median(ems);
    }

    if (options.json) {
        std::printf(
            "{\"scene\": \"%s\", \"triangles\": %zu, \"build_ms\": %.3f, \"min_ms\": %.3f, "
            "\"max_ms\": %.3f, \"mtris_per_s\": %.3f, \"sah_cost\": %.4f, "
            "\"wide_nodes\": %zu, \"leaves\": %zu, \"large_leaves\": %zu, \"depth\": %u",
            options.scene.c_str(), tris, lucent_ms, lo, hi, tris / lucent_ms * 1e-3, stats.sah_cost,
            stats.node_count, stats.leaf_count, stats.large_leaf_count, stats.depth);
        if (peer)
            std::printf(", \"embree_build_ms\": %.3f, \"ratio\": %.4f", embree_ms,
                        embree_ms / lucent_ms);
        std::printf("}\n");
        return 0;
    }
    std::printf("scene %s: %zu triangles, median of %d builds\n", options.scene.c_str(), tris,
                options.repeat);
    std::printf(
        "build %.2f ms (min %.2f, max %.2f) %.2f Mtris/s sah=%.3f wide_nodes=%zu "
        "leaves=%zu large_leaves=%zu depth=%u\n",
        lucent_ms, lo, hi, tris / lucent_ms * 1e-3, stats.sah_cost, stats.node_count,
        stats.leaf_count, stats.large_leaf_count, stats.depth);
    if (peer) {
        std::printf("embree build %.2f ms (RTC_BUILD_QUALITY_HIGH, %u threads)\n", embree_ms,
                    threads);
        std::printf("ratio build %.2fx (embree time / lucent time)\n", embree_ms / lucent_ms);
    }
    return 0;
}

}  // namespace lucent::bench

// `lucent bench rays`: the primary, shadow and diffuse ray sets of shared/BENCH.md traced
// with TriangleAccel on all cores, then with Embree on the same threads in this process.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "accel/triangle_accel.h"
#include "bench/bench_camera.h"
#include "bench/bench_commands.h"
#include "bench/embree_peer.h"
#include "bench/ray_checksums.h"
#include "lucent/error.h"
#include "scene/obj_mesh.h"
#ifdef LUCENT_HAVE_CUDA
#include "bench/bench_rays_cuda.h"
#endif

namespace lucent::bench {

namespace {

namespace fs = std::filesystem;

constexpr float kPi = 3.14159265358979323846f;
constexpr float kOffset = 1e-3f;  // secondary ray origins: p + 1e-3 n (BENCH.md)
constexpr unsigned kChunk = 64;   // rays per work item handed out by the atomic counter

uint32_t hash(uint32_t a) {
    a ^= a >> 16;
    a *= 0x7feb352du;
    a ^= a >> 15;
    a *= 0x846ca68bu;
    a ^= a >> 16;
    return a;
}

/// A set of rays in SoA, and per ray the pixel it came from.
struct RaySet {
    std::vector<float3> origin, direction;
    std::vector<float> tmax;
    std::vector<uint32_t> pixel;
    size_t size() const { return origin.size(); }
    void add(float3 o, float3 d, float t, uint32_t p) {
        origin.push_back(o);
        direction.push_back(d);
        tmax.push_back(t);
        pixel.push_back(p);
    }
};

RaySet primary_rays(const Camera& cam, unsigned w, unsigned h) {
    const float3 fwd = normalize(cam.look - cam.eye);
    const float3 right = normalize(cross(fwd, cam.up));
    const float3 up2 = cross(right, fwd);
    const float t = std::tan(cam.fov / 2 * kPi / 180);
    const float a = (float)w / (float)h;
    RaySet rays;
    for (unsigned y = 0; y < h; ++y)
        for (unsigned x = 0; x < w; ++x) {
            float u = (2 * (x + 0.5f) / w - 1) * t * a;
            float v = (1 - 2 * (y + 0.5f) / h) * t;
            rays.add(cam.eye, normalize(fwd + u * right + v * up2), kInfinity, y * w + x);
        }
    return rays;
}

/// Closest-hit results of a ray set: t (negative on a miss) and the triangle.
struct Hits {
    std::vector<float> t;
    std::vector<uint32_t> prim;
};

/// Shadow and diffuse rays from the primary hits of one engine (BENCH.md).
void secondary_rays(const RaySet& primary, const Hits& hits, const scene::ObjMesh& mesh,
                    float3 light, RaySet& shadow, RaySet& diffuse) {
    for (size_t i = 0; i < primary.size(); ++i) {
        if (hits.t[i] < 0.0f) continue;
        const float3 d = primary.direction[i];
        const float3 p = primary.origin[i] + hits.t[i] * d;
        const uint3 tri = mesh.indices[hits.prim[i]];
        const float3 v0 = mesh.positions[tri.x];
        float3 n = normalize(cross(mesh.positions[tri.y] - v0, mesh.positions[tri.z] - v0));
        if (dot(n, d) > 0.0f) n = -n;
        const float3 o = p + kOffset * n;
        const float3 to_light = light - o;
        const float dist = length(to_light);
        shadow.add(o, to_light / dist, dist, primary.pixel[i]);

        const uint32_t h1 = hash(2 * primary.pixel[i] + 1), h2 = hash(h1);
        const float u1 = (float)(h1 >> 8) / 16777216.0f, u2 = (float)(h2 >> 8) / 16777216.0f;
        const float r = std::sqrt(u1), phi = 2 * kPi * u2;
        const float3 tt = normalize(
            cross(n, std::fabs(n.x) > 0.5f ? make_float3(0, 1, 0) : make_float3(1, 0, 0)));
        const float3 bb = cross(n, tt);
        const float3 dir = normalize(tt * (r * std::cos(phi)) + bb * (r * std::sin(phi)) +
                                     n * std::sqrt(std::max(0.0f, 1 - u1)));
        diffuse.add(o, dir, kInfinity, primary.pixel[i]);
    }
}

/// Mrays/s of the timed repeats: median, min, max.
struct Rate {
    double median = 0, min = 0, max = 0;
};

/// Runs body(i) for every ray on `threads` threads, once to warm up and `repeat` timed times.
template <class Body>
Rate timed(size_t count, unsigned threads, int repeat, Body&& body) {
    std::vector<double> mrays;
    for (int run = -1; run < repeat; ++run) {
        std::atomic<size_t> next{0};
        auto worker = [&] {
            for (;;) {
                size_t begin = next.fetch_add(kChunk, std::memory_order_relaxed);
                if (begin >= count) return;
                size_t end = std::min(count, begin + kChunk);
                for (size_t i = begin; i < end; ++i) body(i);
            }
        };
        auto start = std::chrono::steady_clock::now();
        std::vector<std::thread> pool;
        for (unsigned k = 1; k < threads; ++k) pool.emplace_back(worker);
        worker();
        for (std::thread& t : pool) t.join();
        double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (run >= 0) mrays.push_back(count / s * 1e-6);
    }
    std::sort(mrays.begin(), mrays.end());
    Rate r;
    if (mrays.empty()) return r;
    r.min = mrays.front();
    r.max = mrays.back();
    size_t m = mrays.size();
    r.median = m % 2 ? mrays[m / 2] : 0.5 * (mrays[m / 2 - 1] + mrays[m / 2]);
    return r;
}

/// One engine's figures and checksums for the three ray kinds.
struct EngineResult : RayChecksums {
    Rate primary, shadow, diffuse;
};

/// Traces the three ray sets with closest(o, d, tmax, t&, prim&) and any(o, d, tmax). The
/// shadow and diffuse rays start at the primary hits in `secondary_from` when given (so a
/// peer traces exactly the rays Lucent traced), else at this engine's own; the primary hits
/// are returned in `primary_hits` when asked.
template <class Closest, class Any>
EngineResult run_engine(const RaySet& primary, const scene::ObjMesh& mesh, float3 light,
                        unsigned threads, int repeat, Closest&& closest, Any&& any,
                        Hits* primary_hits = nullptr, const Hits* secondary_from = nullptr) {
    EngineResult res;
    Hits hits{std::vector<float>(primary.size()), std::vector<uint32_t>(primary.size())};
    auto trace_closest = [&](const RaySet& rays, Hits& out) {
        return timed(rays.size(), threads, repeat, [&](size_t i) {
            float t;
            uint32_t prim;
            bool hit = closest(rays.origin[i], rays.direction[i], rays.tmax[i], t, prim);
            out.t[i] = hit ? t : -1.0f;
            out.prim[i] = hit ? prim : 0;
        });
    };
    res.primary = trace_closest(primary, hits);
    for (float t : hits.t)
        if (t >= 0.0f) ++res.primary_hits, res.primary_sum_t += t;

    RaySet shadow, diffuse;
    secondary_rays(primary, secondary_from ? *secondary_from : hits, mesh, light, shadow, diffuse);
    if (primary_hits) *primary_hits = hits;
    std::vector<unsigned char> blocked(shadow.size());
    res.shadow = timed(shadow.size(), threads, repeat, [&](size_t i) {
        blocked[i] = any(shadow.origin[i], shadow.direction[i], shadow.tmax[i]);
    });
    res.shadow_rays = shadow.size();
    for (unsigned char b : blocked) res.occluded += b;

    Hits bounce{std::vector<float>(diffuse.size()), std::vector<uint32_t>(diffuse.size())};
    res.diffuse = trace_closest(diffuse, bounce);
    res.diffuse_rays = diffuse.size();
    for (float t : bounce.t)
        if (t >= 0.0f) ++res.diffuse_hits, res.diffuse_sum_t += t;
    return res;
}

std::string rate_text(const Rate& r) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "%.2f Mrays/s (min %.2f, max %.2f)", r.median, r.min, r.max);
    return buf;
}

void print_engine(const char* prefix, const EngineResult& r) {
    std::printf("%sprimary %s hits=%zu sum_t=%.6e\n", prefix, rate_text(r.primary).c_str(),
                r.primary_hits, r.primary_sum_t);
    std::printf("%sshadow %s rays=%zu occluded=%zu\n", prefix, rate_text(r.shadow).c_str(),
                r.shadow_rays, r.occluded);
    std::printf("%sdiffuse %s rays=%zu hits=%zu sum_t=%.6e\n", prefix, rate_text(r.diffuse).c_str(),
                r.diffuse_rays, r.diffuse_hits, r.diffuse_sum_t);
}

std::string json_engine(const EngineResult& r) {
    char buf[1024];
    auto rate = [](const Rate& x) {
        char b[128];
        std::snprintf(b, sizeof b, "\"mrays\": %.4f, \"min\": %.4f, \"max\": %.4f", x.median, x.min,
                      x.max);
        return std::string(b);
    };
    std::snprintf(buf, sizeof buf,
                  "{\"primary\": {%s, \"hits\": %zu, \"sum_t\": %.9e}, "
                  "\"shadow\": {%s, \"rays\": %zu, \"occluded\": %zu}, "
                  "\"diffuse\": {%s, \"rays\": %zu, \"hits\": %zu, \"sum_t\": %.9e}}",
                  rate(r.primary).c_str(), r.primary_hits, r.primary_sum_t, rate(r.shadow).c_str(),
                  r.shadow_rays, r.occluded, rate(r.diffuse).c_str(), r.diffuse_rays,
                  r.diffuse_hits, r.diffuse_sum_t);
    return buf;
}

}  // namespace

int run_bench_rays(const RaysOptions& options) {
    if (options.width == 0 || options.height == 0)
        throw Error("bench rays: the image size must be at least 1x1");
    if (options.repeat < 1) throw Error("bench rays: --repeat must be at least 1");
    Camera cam = options.has_camera
                     ? Camera{options.eye, options.look, options.up, options.fov, options.light}
                     : find_camera(options.scene);
    const scene::ObjMesh mesh = scene::load_obj_mesh(options.scene);
    const unsigned threads =
        options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
    if (options.backend == "cuda") {
#ifdef LUCENT_HAVE_CUDA
        cuda::CudaRaysInput in;
        in.scene = options.scene;
        in.positions = mesh.positions;
        in.indices = mesh.indices;
        in.camera = cam;
        in.width = options.width, in.height = options.height;
        in.repeat = options.repeat, in.threads = threads, in.json = options.json;
        return cuda::run_bench_rays_cuda(in);
#else
        throw Error(
            "--backend cuda: this lucent was built without the CUDA backend (no CUDA "
            "toolkit at configure time); run with --backend cpu");
#endif
    }

    accel::TriangleAccel accel;
    accel::BuildStats stats;
    accel.build(mesh.positions, mesh.indices, {}, &stats);

    const RaySet primary = primary_rays(cam, options.width, options.height);
    Hits lucent_hits;
    const EngineResult lucent = run_engine(
        primary, mesh, cam.light, threads, options.repeat,
        [&](float3 o, float3 d, float tmax, float& t, uint32_t& prim) {
            accel::TriangleHit hit;
            if (!accel.intersect(o, d, 0.0f, tmax, hit)) return false;
            t = hit.t;
            prim = hit.prim;
            return true;
        },
        [&](float3 o, float3 d, float tmax) { return accel.occluded(o, d, 0.0f, tmax); },
        &lucent_hits);

    const bool peer = options.peer && EmbreePeer::available();
    EngineResult embree;
    double embree_build_ms = 0;
    if (peer) {
        EmbreePeer e(mesh.positions, mesh.indices, threads);
        embree_build_ms = e.build_ms();
        embree = run_engine(
            primary, mesh, cam.light, threads, options.repeat,
            [&](float3 o, float3 d, float tmax, float& t, uint32_t& prim) {
                return e.intersect(o, d, 0.0f, tmax, t, prim);
            },
            [&](float3 o, float3 d, float tmax) { return e.occluded(o, d, 0.0f, tmax); }, nullptr,
            &lucent_hits);  // the same shadow and diffuse rays as Lucent's
    }
    const std::string differences =
        peer ? checksum_differences(lucent, embree, "lucent", "embree") : "";

    if (options.json) {
        std::printf(
            "{\"scene\": \"%s\", \"triangles\": %zu, \"width\": %u, \"height\": %u, "
            "\"threads\": %u, \"repeat\": %d, \"build_ms\": %.3f,\n \"lucent\": %s",
            options.scene.c_str(), mesh.indices.size(), options.width, options.height, threads,
            options.repeat, stats.build_ms, json_engine(lucent).c_str());
        if (peer)
            std::printf(
                ",\n \"embree\": %s,\n \"embree_build_ms\": %.3f, "
                "\"ratio\": {\"primary\": %.4f, \"shadow\": %.4f, \"diffuse\": %.4f}, "
                "\"checksums_agree\": %s",
                json_engine(embree).c_str(), embree_build_ms,
                lucent.primary.median / embree.primary.median,
                lucent.shadow.median / embree.shadow.median,
                lucent.diffuse.median / embree.diffuse.median,
                differences.empty() ? "true" : "false");
        std::printf("}\n");
        return 0;
    }
    std::printf("scene %s: %zu triangles, %ux%u, %u threads, median of %d repeats\n",
                options.scene.c_str(), mesh.indices.size(), options.width, options.height, threads,
                options.repeat);
    std::printf("build %.2f ms (sah %.2f, %zu wide nodes, %zu leaves, %zu of them 5-8 triangles)\n",
                stats.build_ms, stats.sah_cost, stats.node_count, stats.leaf_count,
                stats.large_leaf_count);
    print_engine("", lucent);
    if (!peer) {
        if (options.peer) std::printf("embree: not built in, no peer figures\n");
        return 0;
    }
    std::printf("embree build %.2f ms\n", embree_build_ms);
    print_engine("embree ", embree);
    std::printf("ratio primary %.2fx (lucent/embree)\n",
                lucent.primary.median / embree.primary.median);
    std::printf("ratio shadow %.2fx (lucent/embree)\n",
                lucent.shadow.median / embree.shadow.median);
    std::printf("ratio diffuse %.2fx (lucent/embree)\n",
                lucent.diffuse.median / embree.diffuse.median);
    if (differences.empty())
        std::printf("checksums agree with embree\n");
    else
        std::printf("checksums differ from embree: %s\n", differences.c_str());
    return 0;
}

}  // namespace lucent::bench

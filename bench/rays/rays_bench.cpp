// `lucent bench rays`: the primary, shadow and diffuse ray sets of shared/BENCH.md traced
// with TriangleAccel on all cores and with Embree on the same threads in this process, the
// two engines' timed passes alternating.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "accel/cpu_isa.h"
#include "accel/triangle_accel.h"
#include "bench/common/bench_camera.h"
#include "bench/common/embree_peer.h"
#include "bench/common/rate.h"
#include "bench/common/ray_checksums.h"
#include "bench/common/report.h"
#include "bench/rays/rays_bench.h"
#include "lucent/error.h"
#include "scene/obj_mesh.h"
#ifdef LUCENT_HAVE_CUDA
#include "bench/rays/rays_bench_cuda.h"
#endif

namespace lucent::bench {

namespace {

namespace fs = std::filesystem;

constexpr float kPi = 3.14159265358979323846f;
constexpr float kOffset = 1e-3f;  // secondary ray origins: p + 1e-3 n (BENCH.md)
constexpr unsigned kChunk = 64;   // rays per work item handed out by the atomic counter
static_assert(kChunk % 64 == 0, "a chunk's 1-byte results must fill whole cache lines");

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

/// Allocates on cache-line boundaries. The threads of a pass write their results in chunks
/// of kChunk rays; when a chunk's results start mid-line, two threads working on
/// neighbouring chunks write the same line at once, and every such write moves the line
/// between cores. Unaligned, 1-byte shadow results made Lucent's shadow rays 25 % slower
/// on two threads and Embree's by a varying amount.
template <class T>
struct CacheLineAllocator {
    using value_type = T;
    static constexpr std::align_val_t kLine{64};
    CacheLineAllocator() = default;
    template <class U>
    CacheLineAllocator(const CacheLineAllocator<U>&) noexcept {}
    T* allocate(size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), kLine)); }
    void deallocate(T* p, size_t) noexcept { ::operator delete(p, kLine); }
    template <class U>
    bool operator==(const CacheLineAllocator<U>&) const noexcept {
        return true;
    }
};
template <class T>
using ResultVector = std::vector<T, CacheLineAllocator<T>>;

/// Closest-hit results of a ray set: t (negative on a miss) and the triangle.
struct Hits {
    ResultVector<float> t;
    ResultVector<uint32_t> prim;
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

/// Seconds for body(i) over every ray, on `threads` threads that take chunks of rays from a
/// shared counter. The calling thread only waits. With the caller tracing too, Lucent's
/// two-thread shadow figure moved between 9 and 33 Mrays/s with changes to the caller's
/// stack frame alone; the likely cause is that per ray the workers read the closures that
/// lead to the engine (body, the query, the accel), which live in the caller's frames,
/// beside the stack a tracing caller writes. With the caller waiting, such changes move
/// nothing.
template <class Body>
double timed_pass(size_t count, unsigned threads, const Body& body) {
    // The counter has a cache line to itself, as every worker takes it once per chunk.
    struct alignas(64) Counter {
        std::atomic<size_t> next{0};
    };
    Counter counter;
    auto worker = [&counter, count, body] {  // the worker's own copy of the closure
        for (;;) {
            const size_t begin = counter.next.fetch_add(kChunk, std::memory_order_relaxed);
            if (begin >= count) return;
            const size_t end = std::min(count, begin + kChunk);
            for (size_t i = begin; i < end; ++i) body(i);
        }
    };
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> pool;
    for (unsigned k = 0; k < threads; ++k) pool.emplace_back(worker);
    for (std::thread& t : pool) t.join();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Two engines' rates on the same rays, and the median of the ratios of their neighbouring
/// passes.
struct PairedRates {
    Rate a, b;
    double ratio = 0;  // a's Mrays/s over b's
};

/// Times body_a(i) and body_b(i) over every ray: one untimed warm-up pass each, then
/// `repeat` timed passes each, in the order A B, B A, A B, ... The machines this runs on
/// slow down for seconds at a time (other tenants), so two engines timed one after the
/// other can see different machines; alternating passes lets both see the same one, and
/// each ratio compares two neighbouring passes. Without a peer (with_b false) only A runs.
template <class BodyA, class BodyB>
PairedRates timed_pair(size_t count, unsigned threads, int repeat, BodyA&& body_a, BodyB&& body_b,
                       bool with_b) {
    std::vector<double> mrays_a, mrays_b, ratios;
    timed_pass(count, threads, body_a);
    if (with_b) timed_pass(count, threads, body_b);
    for (int run = 0; run < repeat; ++run) {
        double seconds_a = 0, seconds_b = 0;
        if (run % 2 == 0 || !with_b) {
            seconds_a = timed_pass(count, threads, body_a);
            if (with_b) seconds_b = timed_pass(count, threads, body_b);
        } else {
            seconds_b = timed_pass(count, threads, body_b);
            seconds_a = timed_pass(count, threads, body_a);
        }
        mrays_a.push_back(count / seconds_a * 1e-6);
        if (with_b) {
            mrays_b.push_back(count / seconds_b * 1e-6);
            ratios.push_back(seconds_b / seconds_a);
        }
    }
    return PairedRates{rate_of(mrays_a), rate_of(mrays_b), median_of(ratios)};
}

/// One engine's figures and checksums for the three ray kinds.
struct EngineResult : RayChecksums {
    Rate primary, shadow, diffuse;
};

/// Lucent's figures, the peer's, and Lucent's rate over the peer's per ray kind.
struct BenchResult {
    EngineResult lucent, peer;
    double primary_ratio = 0, shadow_ratio = 0, diffuse_ratio = 0;
};

/// Traces the three ray sets with Lucent and, when `with_peer`, with the peer, each engine
/// given as closest(o, d, tmax, t&, prim&) and any(o, d, tmax). Both trace the shadow and
/// diffuse rays that start at Lucent's primary hits, so their checksums compare line by
/// line.
template <class LucentClosest, class LucentAny, class PeerClosest, class PeerAny>
BenchResult run_engines(const RaySet& primary, const scene::ObjMesh& mesh, float3 light,
                        unsigned threads, int repeat, LucentClosest&& lucent_closest,
                        LucentAny&& lucent_any, PeerClosest&& peer_closest, PeerAny&& peer_any,
                        bool with_peer) {
    BenchResult res;
    auto tracer = [](auto& closest, const RaySet& rays, Hits& out) {
        return [&closest, &rays, &out](size_t i) {
            float t;
            uint32_t prim;
            const bool hit = closest(rays.origin[i], rays.direction[i], rays.tmax[i], t, prim);
            out.t[i] = hit ? t : -1.0f;
            out.prim[i] = hit ? prim : 0;
        };
    };
    auto sum_hits = [](const Hits& hits, size_t& count, double& sum_t) {
        for (float t : hits.t)
            if (t >= 0.0f) ++count, sum_t += t;
    };
    auto hits_for = [](const RaySet& rays) {
        return Hits{ResultVector<float>(rays.size()), ResultVector<uint32_t>(rays.size())};
    };

    Hits lucent_hits = hits_for(primary), peer_hits = hits_for(primary);
    PairedRates p =
        timed_pair(primary.size(), threads, repeat, tracer(lucent_closest, primary, lucent_hits),
                   tracer(peer_closest, primary, peer_hits), with_peer);
    res.lucent.primary = p.a, res.peer.primary = p.b, res.primary_ratio = p.ratio;
    sum_hits(lucent_hits, res.lucent.primary_hits, res.lucent.primary_sum_t);
    sum_hits(peer_hits, res.peer.primary_hits, res.peer.primary_sum_t);

    RaySet shadow, diffuse;
    secondary_rays(primary, lucent_hits, mesh, light, shadow, diffuse);
    ResultVector<unsigned char> lucent_blocked(shadow.size()), peer_blocked(shadow.size());
    p = timed_pair(
        shadow.size(), threads, repeat,
        [&](size_t i) {
            lucent_blocked[i] = lucent_any(shadow.origin[i], shadow.direction[i], shadow.tmax[i]);
        },
        [&](size_t i) {
            peer_blocked[i] = peer_any(shadow.origin[i], shadow.direction[i], shadow.tmax[i]);
        },
        with_peer);
    res.lucent.shadow = p.a, res.peer.shadow = p.b, res.shadow_ratio = p.ratio;
    res.lucent.shadow_rays = res.peer.shadow_rays = shadow.size();
    for (unsigned char b : lucent_blocked) res.lucent.occluded += b;
    for (unsigned char b : peer_blocked) res.peer.occluded += b;

    Hits lucent_bounce = hits_for(diffuse), peer_bounce = hits_for(diffuse);
    p = timed_pair(diffuse.size(), threads, repeat, tracer(lucent_closest, diffuse, lucent_bounce),
                   tracer(peer_closest, diffuse, peer_bounce), with_peer);
    res.lucent.diffuse = p.a, res.peer.diffuse = p.b, res.diffuse_ratio = p.ratio;
    res.lucent.diffuse_rays = res.peer.diffuse_rays = diffuse.size();
    sum_hits(lucent_bounce, res.lucent.diffuse_hits, res.lucent.diffuse_sum_t);
    sum_hits(peer_bounce, res.peer.diffuse_hits, res.peer.diffuse_sum_t);
    return res;
}

void print_engine(const char* prefix, const EngineResult& r) {
    std::printf("%sprimary %s hits=%zu sum_t=%.6e\n", prefix, rate_text(r.primary).c_str(),
                r.primary_hits, r.primary_sum_t);
    std::printf("%sshadow %s rays=%zu occluded=%zu\n", prefix, rate_text(r.shadow).c_str(),
                r.shadow_rays, r.occluded);
    std::printf("%sdiffuse %s rays=%zu hits=%zu sum_t=%.6e\n", prefix, rate_text(r.diffuse).c_str(),
                r.diffuse_rays, r.diffuse_hits, r.diffuse_sum_t);
}

Json json_engine(const EngineResult& r) {
    Json primary = rate_json(r.primary), shadow = rate_json(r.shadow),
         diffuse = rate_json(r.diffuse);
    primary["hits"] = r.primary_hits;
    primary["sum_t"] = r.primary_sum_t;
    shadow["rays"] = r.shadow_rays;
    shadow["occluded"] = r.occluded;
    diffuse["rays"] = r.diffuse_rays;
    diffuse["hits"] = r.diffuse_hits;
    diffuse["sum_t"] = r.diffuse_sum_t;
    return Json{{"primary", primary}, {"shadow", shadow}, {"diffuse", diffuse}};
}

/// What `lucent bench rays` measured on the CPU.
struct RaysResult {
    const RaysOptions* options = nullptr;
    size_t triangles = 0;
    unsigned threads = 0;
    // The traversal variant that ran (cpu_isa.h): the variants' figures are far apart, so
    // every record says which one it is.
    const char* cpu_isa = "";
    accel::BuildStats build;
    BenchResult engines;
    bool peer = false;  // the peer ran
    double embree_build_ms = 0;
    std::string differences;  // of the checksums, lucent against embree ("" when they agree)
};

Json to_json(const RaysResult& r) {
    const RaysOptions& o = *r.options;
    Json j{{"scene", o.scene},
           {"triangles", r.triangles},
           {"width", o.width},
           {"height", o.height},
           {"threads", r.threads},
           {"cpu_isa", r.cpu_isa},
           {"repeat", o.repeat},
           {"build_ms", rounded(r.build.build_ms, 3)},
           {"lucent", json_engine(r.engines.lucent)}};
    if (r.peer) {
        j["embree"] = json_engine(r.engines.peer);
        j["embree_build_ms"] = rounded(r.embree_build_ms, 3);
        j["ratio"] = Json{{"primary", rounded(r.engines.primary_ratio, 4)},
                          {"shadow", rounded(r.engines.shadow_ratio, 4)},
                          {"diffuse", rounded(r.engines.diffuse_ratio, 4)}};
        j["checksums_agree"] = r.differences.empty();
    }
    return j;
}

void print_text(const RaysResult& r) {
    const RaysOptions& o = *r.options;
    std::printf("scene %s: %zu triangles, %ux%u, %u threads, median of %d repeats\n",
                o.scene.c_str(), r.triangles, o.width, o.height, r.threads, o.repeat);
    std::printf(
        "cpu isa %s (the traversal's variant; LUCENT_CPU_ISA=scalar|avx2|avx512 picks one)\n",
        r.cpu_isa);
    std::printf("build %.2f ms (sah %.2f, %zu wide nodes, %zu leaves, %zu of them 5-8 triangles)\n",
                r.build.build_ms, r.build.sah_cost, r.build.node_count, r.build.leaf_count,
                r.build.large_leaf_count);
    print_engine("", r.engines.lucent);
    if (!r.peer) {
        if (o.peer) std::printf("embree: not built in, no peer figures\n");
        return;
    }
    std::printf("embree build %.2f ms\n", r.embree_build_ms);
    print_engine("embree ", r.engines.peer);
    // Each ratio is the median over the repeats of two neighbouring passes' ratio.
    std::printf("ratio primary %.2fx (lucent/embree)\n", r.engines.primary_ratio);
    std::printf("ratio shadow %.2fx (lucent/embree)\n", r.engines.shadow_ratio);
    std::printf("ratio diffuse %.2fx (lucent/embree)\n", r.engines.diffuse_ratio);
    if (r.differences.empty())
        std::printf("checksums agree with embree\n");
    else
        std::printf("checksums differ from embree: %s\n", r.differences.c_str());
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

    RaysResult result;
    result.options = &options;
    result.triangles = mesh.indices.size();
    result.threads = threads;
    accel::TriangleAccel accel;
    accel.build(mesh.positions, mesh.indices, {}, &result.build);

    result.peer = options.peer && EmbreePeer::available();
    const bool peer = result.peer;
    std::optional<EmbreePeer> embree_peer;
    if (peer) embree_peer.emplace(mesh.positions, mesh.indices, threads);
    result.embree_build_ms = peer ? embree_peer->build_ms() : 0.0;

    const RaySet primary = primary_rays(cam, options.width, options.height);
    result.engines = run_engines(
        primary, mesh, cam.light, threads, options.repeat,
        [&](float3 o, float3 d, float tmax, float& t, uint32_t& prim) {
            accel::TriangleHit hit;
            if (!accel.intersect(o, d, 0.0f, tmax, hit)) return false;
            t = hit.t;
            prim = hit.prim;
            return true;
        },
        [&](float3 o, float3 d, float tmax) { return accel.occluded(o, d, 0.0f, tmax); },
        [&](float3 o, float3 d, float tmax, float& t, uint32_t& prim) {
            return embree_peer->intersect(o, d, 0.0f, tmax, t, prim);
        },
        [&](float3 o, float3 d, float tmax) { return embree_peer->occluded(o, d, 0.0f, tmax); },
        peer);
    result.cpu_isa = accel::cpu_isa_name(accel::active_cpu_isa());
    if (peer)
        result.differences =
            checksum_differences(result.engines.lucent, result.engines.peer, "lucent", "embree");
    report(result, options.json);
    return 0;
}

}  // namespace lucent::bench

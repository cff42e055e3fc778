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
#include "bench/common/option_checks.h"
#include "bench/common/rate.h"
#include "bench/common/ray_checksums.h"
#include "bench/common/report.h"
#include "bench/rays/programs_bench.h"
#include "bench/rays/ray_sets.h"
#include "bench/rays/rays_bench.h"
#include "bench/rays/stream_passes.h"
#include "lucent/error.h"
#include "scene/obj_mesh.h"
#ifdef LUCENT_HAVE_CUDA
#include "bench/gpu/ray_bench.h"
#include "bench/rays/rays_bench_cuda.h"
#endif

namespace lucent::bench {

namespace {

namespace fs = std::filesystem;

constexpr unsigned kChunk = 64;  // rays per work item handed out by the atomic counter
static_assert(kChunk % 64 == 0, "a chunk's 1-byte results must fill whole cache lines");

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

/// The hits of `rays`, one slot per ray.
Hits hits_for(const RaySet& rays) {
    return Hits{ResultVector<float>(rays.size()), ResultVector<uint32_t>(rays.size())};
}

/// The body of a closest-hit pass: ray i's t (-1 on a miss) and triangle into `out`.
template <class Closest>
auto closest_body(Closest& closest, const RaySet& rays, Hits& out) {
    return [&closest, &rays, &out](size_t i) {
        float t;
        uint32_t prim;
        const bool hit = closest(rays.origin[i], rays.direction[i], rays.tmax[i], t, prim);
        out.t[i] = hit ? t : -1.0f;
        out.prim[i] = hit ? prim : 0;
    };
}

/// The body of an occlusion pass: whether ray i is blocked into `out`.
template <class Any>
auto occlusion_body(Any& any, const RaySet& rays, ResultVector<unsigned char>& out) {
    return [&any, &rays, &out](size_t i) {
        out[i] = any(rays.origin[i], rays.direction[i], rays.tmax[i]);
    };
}

/// Two engines' rates on the same rays, and the median of the ratios of their neighbouring
/// passes.
struct PairedRates {
    Rate a, b;
    double ratio = 0;  // a's Mrays/s over b's
};

/// Times two engines' passes over the same `count` rays, each pass given as a callable
/// returning its seconds: one untimed warm-up pass each, then `repeat` timed passes each, in
/// the order A B, B A, A B, ... The machines this runs on slow down for seconds at a time
/// (other tenants), so two engines timed one after the other can see different machines;
/// alternating passes lets both see the same one, and each ratio compares two neighbouring
/// passes. Without a peer (with_b false) only A runs.
template <class PassA, class PassB>
PairedRates timed_pair(size_t count, int repeat, PassA&& pass_a, PassB&& pass_b, bool with_b) {
    std::vector<double> mrays_a, mrays_b, ratios;
    pass_a();
    if (with_b) pass_b();
    for (int run = 0; run < repeat; ++run) {
        double seconds_a = 0, seconds_b = 0;
        if (run % 2 == 0 || !with_b) {
            seconds_a = pass_a();
            if (with_b) seconds_b = pass_b();
        } else {
            seconds_b = pass_b();
            seconds_a = pass_a();
        }
        mrays_a.push_back(count / seconds_a * 1e-6);
        if (with_b) {
            mrays_b.push_back(count / seconds_b * 1e-6);
            ratios.push_back(seconds_b / seconds_a);
        }
    }
    return PairedRates{rate_of(mrays_a), rate_of(mrays_b), median_of(ratios)};
}

/// timed_pair for two engines' per-ray bodies: body(i) traces ray i (timed_pass).
template <class BodyA, class BodyB>
PairedRates timed_pair_of_bodies(size_t count, unsigned threads, int repeat, const BodyA& body_a,
                                 const BodyB& body_b, bool with_b) {
    return timed_pair(
        count, repeat, [&] { return timed_pass(count, threads, body_a); },
        [&] { return timed_pass(count, threads, body_b); }, with_b);
}

/// One engine's figures and checksums for the three ray kinds.
struct EngineResult : RayChecksums {
    Rate primary, shadow, diffuse;
};

/// Lucent's figures, the peer's, and Lucent's rate over the peer's per ray kind; with
/// streams, the figures of Lucent's stream queries and their rate over the peer's.
struct BenchResult {
    EngineResult lucent, peer;
    double primary_ratio = 0, shadow_ratio = 0, diffuse_ratio = 0;
    bool with_streams = false;
    EngineResult streams;
    double stream_primary_ratio = 0, stream_shadow_ratio = 0, stream_diffuse_ratio = 0;
};

/// Traces the three ray sets with Lucent and, when `with_peer`, with the peer, each engine
/// given as closest(o, d, tmax, t&, prim&) and any(o, d, tmax). Both trace the shadow and
/// diffuse rays that start at Lucent's primary hits, so their checksums compare line by
/// line. With `streams`, each set is traced again by Lucent's stream queries, paired with
/// the peer's passes of its own.
template <class LucentClosest, class LucentAny, class PeerClosest, class PeerAny>
BenchResult run_engines(const RaySet& primary, const scene::ObjMesh& mesh, float3 light,
                        unsigned threads, int repeat, LucentClosest&& lucent_closest,
                        LucentAny&& lucent_any, PeerClosest&& peer_closest, PeerAny&& peer_any,
                        bool with_peer, StreamPasses* streams = nullptr) {
    BenchResult res;
    res.with_streams = streams != nullptr;
    auto sum_hits = [](const Hits& hits, size_t& count, double& sum_t) {
        for (float t : hits.t)
            if (t >= 0.0f) ++count, sum_t += t;
    };
    auto sum_stream_hits = [](const std::vector<accel::StreamHit>& hits, size_t& count,
                              double& sum_t) {
        for (const accel::StreamHit& h : hits)
            if (h.prim != accel::kStreamMiss) ++count, sum_t += h.t;
    };
    // The stream engine against the peer on one closest-hit set; the peer's answers are
    // already checked against the kernels', so they are not kept.
    auto stream_closest_pair = [&](const RaySet& rays, std::vector<accel::StreamHit>& hits) {
        const std::vector<accel::StreamRay> stream = stream_rays(rays);
        Hits peer_hits = hits_for(rays);
        const auto peer_body = closest_body(peer_closest, rays, peer_hits);
        return timed_pair(
            rays.size(), repeat, [&] { return streams->closest(stream, hits); },
            [&] { return timed_pass(rays.size(), threads, peer_body); }, with_peer);
    };

    Hits lucent_hits = hits_for(primary), peer_hits = hits_for(primary);
    PairedRates p = timed_pair_of_bodies(primary.size(), threads, repeat,
                                         closest_body(lucent_closest, primary, lucent_hits),
                                         closest_body(peer_closest, primary, peer_hits), with_peer);
    res.lucent.primary = p.a, res.peer.primary = p.b, res.primary_ratio = p.ratio;
    sum_hits(lucent_hits, res.lucent.primary_hits, res.lucent.primary_sum_t);
    sum_hits(peer_hits, res.peer.primary_hits, res.peer.primary_sum_t);
    if (streams) {
        std::vector<accel::StreamHit> hits(primary.size());
        p = stream_closest_pair(primary, hits);
        res.streams.primary = p.a, res.stream_primary_ratio = p.ratio;
        sum_stream_hits(hits, res.streams.primary_hits, res.streams.primary_sum_t);
    }

    RaySet shadow, diffuse;
    secondary_rays(primary, lucent_hits.t.data(), lucent_hits.prim.data(), mesh, light, shadow,
                   diffuse);
    ResultVector<unsigned char> lucent_blocked(shadow.size()), peer_blocked(shadow.size());
    p = timed_pair_of_bodies(shadow.size(), threads, repeat,
                             occlusion_body(lucent_any, shadow, lucent_blocked),
                             occlusion_body(peer_any, shadow, peer_blocked), with_peer);
    res.lucent.shadow = p.a, res.peer.shadow = p.b, res.shadow_ratio = p.ratio;
    res.lucent.shadow_rays = res.peer.shadow_rays = shadow.size();
    for (unsigned char b : lucent_blocked) res.lucent.occluded += b;
    for (unsigned char b : peer_blocked) res.peer.occluded += b;
    if (streams) {
        const std::vector<accel::StreamRay> stream = stream_rays(shadow);
        std::vector<uint8_t> blocked(shadow.size());
        const auto peer_body = occlusion_body(peer_any, shadow, peer_blocked);
        p = timed_pair(
            shadow.size(), repeat, [&] { return streams->occluded(stream, blocked); },
            [&] { return timed_pass(shadow.size(), threads, peer_body); }, with_peer);
        res.streams.shadow = p.a, res.stream_shadow_ratio = p.ratio;
        res.streams.shadow_rays = shadow.size();
        for (uint8_t b : blocked) res.streams.occluded += b;
    }

    Hits lucent_bounce = hits_for(diffuse), peer_bounce = hits_for(diffuse);
    p = timed_pair_of_bodies(diffuse.size(), threads, repeat,
                             closest_body(lucent_closest, diffuse, lucent_bounce),
                             closest_body(peer_closest, diffuse, peer_bounce), with_peer);
    res.lucent.diffuse = p.a, res.peer.diffuse = p.b, res.diffuse_ratio = p.ratio;
    res.lucent.diffuse_rays = res.peer.diffuse_rays = diffuse.size();
    sum_hits(lucent_bounce, res.lucent.diffuse_hits, res.lucent.diffuse_sum_t);
    sum_hits(peer_bounce, res.peer.diffuse_hits, res.peer.diffuse_sum_t);
    if (streams) {
        std::vector<accel::StreamHit> hits(diffuse.size());
        p = stream_closest_pair(diffuse, hits);
        res.streams.diffuse = p.a, res.stream_diffuse_ratio = p.ratio;
        res.streams.diffuse_rays = diffuse.size();
        sum_stream_hits(hits, res.streams.diffuse_hits, res.streams.diffuse_sum_t);
    }
    return res;
}

/// Seconds of one pass of an engine over `rays`: closest hits for primary and diffuse
/// rays, occlusion for shadow rays, the answers written as run_engines writes them.
template <class Closest, class Any>
double engine_pass(RayKind kind, const RaySet& rays, unsigned threads, Closest& closest, Any& any) {
    if (kind == RayKind::kShadow) {
        ResultVector<unsigned char> blocked(rays.size());
        return timed_pass(rays.size(), threads, occlusion_body(any, rays, blocked));
    }
    Hits out = hits_for(rays);
    return timed_pass(rays.size(), threads, closest_body(closest, rays, out));
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
    std::string stream_differences;  // the stream queries' checksums against the kernels'
    // --programs: the ray sets through rays_programs.h, and its checksums against the kernels'.
    // Both forms of the module's entry points: each ray waited for, and deferred.
    bool programs = false;
    ProgramsResult program_figures, deferred_figures;
    std::string program_differences, deferred_differences;
};

/// The name of a form of the programs in the text report.
const char* form_name(bool deferred) {
    return deferred ? "deferred programs" : "programs";
}

/// The programs' figures as an EngineResult, for the shared printers.
EngineResult engine_of(const ProgramsResult& p) {
    EngineResult r;
    static_cast<RayChecksums&>(r) = p;
    r.primary = p.primary, r.shadow = p.shadow, r.diffuse = p.diffuse;
    return r;
}

/// The programs' rate over another engine's, per ray set: the median of the paired passes'
/// ratios where the run paired them with this engine's (`paired` is its position), else
/// the ratio of the two medians.
PairedRatios programs_ratios(const ProgramsResult& p, const EngineResult& other, size_t paired) {
    if (paired < p.paired.size()) return p.paired[paired];
    return PairedRatios{median_ratio(p.primary, other.primary),
                        median_ratio(p.shadow, other.shadow),
                        median_ratio(p.diffuse, other.diffuse)};
}

Json programs_json(const ProgramsResult& p, const EngineResult& kernels, const EngineResult* peer,
                   const std::string& differences) {
    Json j = json_engine(engine_of(p));
    j["backend"] = p.backend;
    j["timing"] = p.timing;
    auto ratios = [](const PairedRatios& r) {
        return Json{{"primary", rounded(r.primary, 4)},
                    {"shadow", rounded(r.shadow, 4)},
                    {"diffuse", rounded(r.diffuse, 4)}};
    };
    j["ratio_to_kernels"] = ratios(programs_ratios(p, kernels, 0));
    if (peer) j["ratio_to_embree"] = ratios(programs_ratios(p, *peer, 1));
    j["checksums_agree"] = differences.empty();
    return j;
}

/// The programs' lines: figures, ratios to the kernels (and to Embree), checksums.
void print_programs(const ProgramsResult& p, bool deferred, const EngineResult& kernels,
                    const EngineResult* peer, const std::string& differences) {
    const char* name = form_name(deferred);
    std::printf("%s on %s (rays_programs.h%s through a Context; %s time per launch)\n", name,
                p.backend.c_str(), deferred ? "'s *_deferred entries" : "",
                p.timing == "kernel" ? "the megakernel's CUDA-event" : "the whole");
    print_engine((std::string(name) + " ").c_str(), engine_of(p));
    auto ratios = [&](const char* what, const PairedRatios& r) {
        std::printf("ratio %s/%s primary %.2fx, shadow %.2fx, diffuse %.2fx\n", name, what,
                    r.primary, r.shadow, r.diffuse);
    };
    ratios("kernels", programs_ratios(p, kernels, 0));
    if (peer) ratios("embree", programs_ratios(p, *peer, 1));
    if (differences.empty())
        std::printf("%s' checksums agree with the kernels\n", name);
    else
        std::printf("%s' checksums differ from the kernels: %s\n", name, differences.c_str());
}
/// Both forms' lines.
void print_programs(const RaysResult& r, const EngineResult* peer) {
    print_programs(r.program_figures, false, r.engines.lucent, peer, r.program_differences);
    print_programs(r.deferred_figures, true, r.engines.lucent, peer, r.deferred_differences);
}

/// Lucent's bare CPU traversal as the (closest, occluded) bodies run_engines times.
auto closest_query(const accel::TriangleAccel& accel) {
    return [&accel](float3 o, float3 d, float tmax, float& t, uint32_t& prim) {
        accel::TriangleHit hit;
        if (!accel.intersect(o, d, 0.0f, tmax, hit)) return false;
        t = hit.t;
        prim = hit.prim;
        return true;
    };
}
auto occluded_query(const accel::TriangleAccel& accel) {
    return [&accel](float3 o, float3 d, float tmax) { return accel.occluded(o, d, 0.0f, tmax); };
}

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
    if (r.engines.with_streams) {
        Json streams = json_engine(r.engines.streams);
        if (r.peer) {
            streams["ratio_to_embree"] = Json{{"primary", rounded(r.engines.stream_primary_ratio, 4)},
                                              {"shadow", rounded(r.engines.stream_shadow_ratio, 4)},
                                              {"diffuse", rounded(r.engines.stream_diffuse_ratio, 4)}};
        }
        streams["checksums_agree_with_kernels"] = r.stream_differences.empty();
        j["streams"] = streams;
    }
    if (r.programs) {
        const EngineResult* peer = r.peer ? &r.engines.peer : nullptr;
        j["programs"] =
            programs_json(r.program_figures, r.engines.lucent, peer, r.program_differences);
        j["programs_deferred"] =
            programs_json(r.deferred_figures, r.engines.lucent, peer, r.deferred_differences);
    }
    return j;
}

/// The stream queries' lines: figures, ratios to Embree, checksums against the kernels'.
void print_streams(const RaysResult& r) {
    if (!r.engines.with_streams) return;
    std::printf("streams (TriangleAccel's stream queries, batches of up to %zu rays a thread)\n",
                accel::kStreamBatch);
    print_engine("streams ", r.engines.streams);
    if (r.peer)
        std::printf("ratio streams/embree primary %.2fx, shadow %.2fx, diffuse %.2fx\n",
                    r.engines.stream_primary_ratio, r.engines.stream_shadow_ratio,
                    r.engines.stream_diffuse_ratio);
    if (r.stream_differences.empty())
        std::printf("streams' checksums agree with the kernels\n");
    else
        std::printf("streams' checksums differ from the kernels: %s\n",
                    r.stream_differences.c_str());
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
        print_streams(r);
        if (r.programs) print_programs(r, nullptr);
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
    print_streams(r);
    if (r.programs) print_programs(r, &r.engines.peer);
}

#ifdef LUCENT_HAVE_CUDA
/// `--programs --backend cuda`: the programs on the GPU, their checksums against the CPU
/// kernels' on the same rays (TriangleAccel, one pass of each set).
void run_programs_cuda(const RaysOptions& options, const scene::ObjMesh& mesh, const Camera& cam,
                       unsigned threads, Json& document) {
    accel::TriangleAccel accel;
    accel.build(mesh.positions, mesh.indices, {});
    const RaySet primary = primary_rays(cam, options.width, options.height);
    ProgramsInput in;
    in.mesh = &mesh, in.primary = &primary, in.light = cam.light;
    in.backend = BackendKind::kCuda, in.repeat = options.repeat;
    in.builder = options.builder;
    in.tree_upgrades = options.tree_upgrades;
    // The kernels' ray order (LUCENT_BENCH_TILES), so that both trace the same warps' rays.
    in.width = options.width, in.height = options.height;
    in.tile_order = cuda::env_flag("LUCENT_BENCH_TILES", true);
    auto none = [](auto&&...) { return false; };
    const BenchResult kernels =
        run_engines(primary, mesh, cam.light, threads, 1, closest_query(accel),
                    occluded_query(accel), none, none, false);
    for (const bool deferred : {false, true}) {
        in.deferred = deferred;
        const ProgramsResult p = run_programs(in);
        const char* name = form_name(deferred);
        const std::string differences = checksum_differences(p, kernels.lucent, name, "kernels");
        if (options.json) {
            Json j = json_engine(engine_of(p));
            j["backend"] = p.backend;
            j["timing"] = p.timing;
            j["checksums_agree_with_cpu_kernels"] = differences.empty();
            j["kernel_variants"] = Json{{"primary", p.primary_variant},
                                        {"shadow", p.shadow_variant},
                                        {"diffuse", p.diffuse_variant}};
            j["trees_upgraded"] = p.trees_upgraded;
            // Beside the kernels' figures: one document.
            document[deferred ? "programs_deferred" : "programs"] = j;
            continue;
        }
        std::printf("%s on %s (rays_programs.h%s through a Context; %s time per launch)\n", name,
                    p.backend.c_str(), deferred ? "'s *_deferred entries" : "",
                    p.timing == "kernel" ? "the megakernel's CUDA-event" : "the whole");
        print_engine((std::string(name) + " ").c_str(), engine_of(p));
        std::printf("%s' kernel variants: primary %s, shadow %s, diffuse %s\n", name,
                    p.primary_variant.c_str(), p.shadow_variant.c_str(), p.diffuse_variant.c_str());
        if (p.trees_upgraded > 0)
            std::printf(
                "%s' tree: built on the GPU, then upgraded to the host's tree with "
                "spatial splits before the first launch\n", name);
        if (differences.empty())
            std::printf("%s' checksums agree with the CPU kernels\n", name);
        else
            std::printf("%s' checksums differ from the CPU kernels: %s\n", name,
                        differences.c_str());
    }
}
#endif

}  // namespace

namespace {
/// The checks of the options that the CLI's parser does not make for a C++ or Python caller
/// (each names the option as both spell it).
void check_options(const RaysOptions& options) {
    if (options.scene.empty())
        throw Error("bench rays: no scene (scene, --scene); give an OBJ file's path");
    require_image_size("bench rays", options.width, options.height);
    require_in_range("bench rays", "repeat (--repeat)", options.repeat, 1, 1000);
    require_in_range("bench rays", "threads (--threads)", options.threads, 0, 4096);
    if (options.backend != "cpu" && options.backend != "cuda")
        throw Error("bench rays: backend (--backend) is \"" + options.backend +
                    "\"; use \"cpu\" or \"cuda\"");
    if (!options.has_camera) return;
    if (!(options.fov > 0.0f && options.fov < 180.0f))
        throw Error("bench rays: fov (--fov) is " + std::to_string(options.fov) +
                    " degrees; it must lie in (0, 180)");
    const float3 points[] = {options.eye, options.look, options.up, options.light};
    for (const float3& p : points)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw Error(
                "bench rays: the camera (eye, look, up, light) has a value that is not "
                "a finite number");
    const float3 view = options.look - options.eye;
    if (dot(view, view) == 0.0f || dot(options.up, options.up) == 0.0f)
        throw Error("bench rays: the camera's eye and look are the same point, or up is zero; "
                    "give an eye apart from look and a nonzero up");
}
}  // namespace

std::string bench_rays_json(RaysOptions options) {
    return captured_document("bench rays", std::move(options), run_bench_rays);
}

int run_bench_rays(const RaysOptions& options) {
    check_options(options);
    // The scene first: a missing or malformed file is named as such, before its cameras.txt.
    const scene::ObjMesh mesh = scene::load_obj_mesh(options.scene);
    Camera cam = options.has_camera
                     ? Camera{options.eye, options.look, options.up, options.fov, options.light}
                     : find_camera(options.scene);
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
        // The tree the engine traces: the GPU's is upgraded to the host's with splits.
        in.spatial_splits =
            options.builder == Builder::kBinnedSah || options.tree_upgrades != TreeUpgrades::kOff;
        Json document;
        if (options.json && options.programs) in.json_out = &document;
        const int code = cuda::run_bench_rays_cuda(in);
        if (code == 0 && options.programs) run_programs_cuda(options, mesh, cam, threads, document);
        if (in.json_out) print_json(document);
        return code;
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
    StreamPasses streams(accel, threads);
    result.engines = run_engines(
        primary, mesh, cam.light, threads, options.repeat, closest_query(accel),
        occluded_query(accel),
        [&](float3 o, float3 d, float tmax, float& t, uint32_t& prim) {
            return embree_peer->intersect(o, d, 0.0f, tmax, t, prim);
        },
        [&](float3 o, float3 d, float tmax) { return embree_peer->occluded(o, d, 0.0f, tmax); },
        peer, &streams);
    result.stream_differences =
        checksum_differences(result.engines.streams, result.engines.lucent, "streams", "kernels");
    result.cpu_isa = accel::cpu_isa_name(accel::active_cpu_isa());
    if (options.programs) {
        ProgramsInput in;
        in.mesh = &mesh, in.primary = &primary, in.light = cam.light;
        in.backend = BackendKind::kCpu, in.threads = threads, in.repeat = options.repeat;
        in.builder = options.builder;
        // The kernels' pass and the peer's beside each launch, so that the programs' ratios
        // to them compare neighbouring passes, as the kernels' ratio to the peer does.
        auto kernel_closest = closest_query(accel);
        auto kernel_any = occluded_query(accel);
        auto peer_closest = [&](float3 o, float3 d, float tmax, float& t, uint32_t& prim) {
            return embree_peer->intersect(o, d, 0.0f, tmax, t, prim);
        };
        auto peer_any = [&](float3 o, float3 d, float tmax) {
            return embree_peer->occluded(o, d, 0.0f, tmax);
        };
        in.paired_passes = [&](RayKind kind, const RaySet& rays) {
            std::vector<double> seconds;
            seconds.push_back(engine_pass(kind, rays, threads, kernel_closest, kernel_any));
            if (peer) seconds.push_back(engine_pass(kind, rays, threads, peer_closest, peer_any));
            return seconds;
        };
        result.programs = true;
        result.program_figures = run_programs(in);
        result.program_differences = checksum_differences(
            result.program_figures, result.engines.lucent, "programs", "kernels");
        in.deferred = true;
        result.deferred_figures = run_programs(in);
        result.deferred_differences = checksum_differences(
            result.deferred_figures, result.engines.lucent, "deferred programs", "kernels");
    }
    if (peer)
        result.differences =
            checksum_differences(result.engines.lucent, result.engines.peer, "lucent", "embree");
    report(result, options.json);
    return 0;
}

}  // namespace lucent::bench

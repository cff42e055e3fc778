#include "bench/rays/programs_bench.h"

#include <cstdlib>
#include <functional>
#include <numeric>
#include <vector>

#include "bench/common/input_buffer.h"
#include "bench/rays/rays_programs.h"
#include "cuda/device/lucent_gpu/ray_order.cuh"
#include "lucent/lucent.h"
#include "samples/stages.h"

namespace lucent::bench {

namespace {

namespace programs = lucent_bench_rays;

constexpr unsigned kPrimaryEntry = 0, kShadowEntry = 1, kDiffuseEntry = 2;

/// The order in which a set's rays are launched: the indices of `rays`, in pixel order, or
/// (tile_order) by their pixel's place in the 8x4 tiles of a width x height image
/// (gpu_tiled_pixel). Every set has at most one ray a pixel.
std::vector<uint32_t> launch_order(const RaySet& rays, const ProgramsInput& in) {
    std::vector<uint32_t> order(rays.size());
    std::iota(order.begin(), order.end(), 0u);
    const size_t pixels = size_t(in.width) * in.height;
    if (!in.tile_order || pixels == 0) return order;
    std::vector<uint32_t> ray_of_pixel(pixels, ~0u);
    for (size_t i = 0; i < rays.size(); ++i) ray_of_pixel.at(rays.pixel[i]) = uint32_t(i);
    order.clear();
    for (unsigned r = 0; r < pixels; ++r) {
        const uint32_t i = ray_of_pixel[gpu::gpu_tiled_pixel(r, in.width, in.height)];
        if (i != ~0u) order.push_back(i);
    }
    return order;
}

/// A ray-generation program with its own ray set bound to it (its own variable scope), two
/// float4s a ray: (origin, tmin), (direction, tmax); launch index j traces rays[order[j]].
std::shared_ptr<Program> program_for(Context& ctx, const char* name, const RaySet& rays,
                                     const std::vector<uint32_t>& order) {
    std::vector<float4> packed(2 * rays.size());
    for (size_t j = 0; j < rays.size(); ++j) {
        const uint32_t i = order[j];
        const float3 o = rays.origin[i], d = rays.direction[i];
        packed[2 * j] = float4{o.x, o.y, o.z, 0.0f};  // BENCH.md: tmin is 0 for every ray
        packed[2 * j + 1] = float4{d.x, d.y, d.z, rays.tmax[i]};
    }
    auto program = ctx.create_program(name);
    (*program)["rays"] = input_buffer(ctx, packed);
    return program;
}

/// The kernel variant a CUDA launch ran (empty on the CPU): as compiled, or compiled with
/// registers capped, trace() inlined (with lanes refilled) or both
/// (ContextOptions::register_variants).
std::string variant_of(const LaunchReport& report) {
    if (report.kernel_ms <= 0) return "";
    std::string variant;
    auto add = [&](const std::string& part) { variant += (variant.empty() ? "" : ", ") + part; };
    if (report.trace_inlined) add("trace inlined");
    if (report.lanes_refilled) add("lanes refilled");
    if (report.registers_capped) add("registers capped to " + std::to_string(report.register_cap));
    return variant.empty() ? "as compiled" : variant;
}

/// Mrays/s of `repeat` launches of `entry` over `count` rays, all after the tuning: the
/// first launch compiles the scene and, on the GPU, the kernel; trial launches are left out
/// as the samples' `render --repeat` leaves them (samples::SteadyLaunches), so a median of
/// 5 is never a trial shape's time.
/// With `paired` (a set's PairedPasses bound to its rays), each timed launch also has the
/// paired engines' passes beside it, in turn before and after it; `ratios[e]` gets the
/// median of engine e's pass seconds over its neighbouring launch's.
/// `trees_upgraded` counts the launches' LaunchReport::trees_upgraded.
Rate timed_launches(Context& ctx, unsigned entry, size_t count, int repeat, std::string& timing,
                    std::string& variant, const std::function<std::vector<double>()>& paired,
                    std::vector<double>& ratios, unsigned& trees_upgraded) {
    samples::SteadyLaunches steady;
    ctx.launch(entry, unsigned(count));
    trees_upgraded += ctx.last_launch().trees_upgraded;
    if (paired) paired();  // their warm-up pass, as the launch above is the programs'
    std::vector<std::vector<double>> pair_ratios;
    const int most = repeat + int(samples::kMostTrialLaunches);
    for (int launch = 1; launch < most && int(steady.ms.size()) < repeat; ++launch) {
        const bool paired_first = paired && launch % 2 == 0;
        std::vector<double> passes;
        if (paired_first) passes = paired();
        ctx.launch(entry, unsigned(count));
        const LaunchReport& report = ctx.last_launch();
        trees_upgraded += report.trees_upgraded;
        if (paired && !paired_first) passes = paired();
        const size_t kept = steady.ms.size();
        steady.add(report);  // a launch-shape trial clears the launches before it
        if (steady.ms.size() <= kept) pair_ratios.clear();
        if (!report.launch_shape_trial) {
            variant = variant_of(report);  // the tuning's choice
            const double launch_s =
                (report.kernel_ms > 0 ? report.kernel_ms : report.launch_ms) * 1e-3;
            pair_ratios.resize(passes.size());
            for (size_t e = 0; e < passes.size(); ++e)
                pair_ratios[e].push_back(launch_s > 0 ? passes[e] / launch_s : 0.0);
        }
    }
    ratios.clear();
    for (const std::vector<double>& r : pair_ratios) ratios.push_back(median_of(r));
    std::vector<double> mrays;
    for (size_t i = 0; i < steady.ms.size(); ++i)
        mrays.push_back(
            samples::launch_mrays(double(count), steady.kernel_ms[i], steady.ms[i], timing));
    return rate_of(mrays);
}

}  // namespace

ProgramsResult run_programs(const ProgramsInput& in) {
    const scene::ObjMesh& mesh = *in.mesh;
    const RaySet& primary = *in.primary;
    ContextOptions options;
    options.backend = in.backend;
    options.threads = in.threads;
    // The register-capped variants of the GPU kernels compiled with them, not in the
    // background, so that every ray set is timed with all of its shapes tried.
    options.register_variants = RegisterVariants::kWithKernel;
    options.tree_upgrades = in.tree_upgrades;
    Context ctx(options);
    ctx.add_module("lucent_bench_rays");
    ctx.set_ray_type<programs::RayHit>(programs::kBenchRay, "bench");
    ctx.set_miss_program(programs::kBenchRay, ctx.create_program("record_miss"));

    auto triangles = ctx.create_geometry_triangles();
    triangles->set_vertices(input_buffer(ctx, mesh.positions));
    triangles->set_indices(input_buffer(ctx, mesh.indices));
    auto material = ctx.create_material();
    material->set_closest_hit(programs::kBenchRay, ctx.create_program("record_hit"));
    auto instance = ctx.create_geometry_instance();
    instance->set_geometry(triangles);
    instance->add_material(material);
    auto group = ctx.create_geometry_group();
    group->set_acceleration(ctx.create_acceleration(in.builder));
    group->add_child(instance);
    ctx["scene"] = group;

    ProgramsResult res;
    res.backend = ctx.backend_name();
    auto closest_outputs = [&](Program& program, size_t count) {
        auto hits = ctx.create_buffer<programs::RayHit>(BufferType::kOutput, unsigned(count));
        program["hits"] = hits;
        return hits;
    };
    // The answers back in the rays' own order (launch index j answered rays[order[j]]).
    auto in_ray_order = [](const programs::RayHit* launched, const std::vector<uint32_t>& order) {
        std::vector<programs::RayHit> hits(order.size());
        for (size_t j = 0; j < order.size(); ++j) hits[order[j]] = launched[j];
        return hits;
    };
    auto sum_hits = [](const std::vector<programs::RayHit>& hit, size_t& hits, double& sum_t) {
        for (const programs::RayHit& h : hit)
            if (h.t >= 0.0f) ++hits, sum_t += h.t;
    };

    // Primary rays, then the shadow and diffuse sets from their hits (BENCH.md).
    const std::vector<uint32_t> primary_order = launch_order(primary, in);
    const char* closest_entry = in.deferred ? "closest_rays_deferred" : "closest_rays";
    const char* shadow_entry = in.deferred ? "shadow_rays_deferred" : "shadow_rays";
    auto primary_program = program_for(ctx, closest_entry, primary, primary_order);
    auto primary_hits = closest_outputs(*primary_program, primary.size());
    // Each set's entry point is added when its rays exist (every entry needs its program).
    ctx.set_entry_point_count(1);
    ctx.set_ray_generation_program(kPrimaryEntry, primary_program);
    // The paired engines' passes over a set's rays, and where their ratios go.
    std::vector<double> primary_ratios, shadow_ratios, diffuse_ratios;
    auto paired_on = [&](RayKind kind, const RaySet& rays) -> std::function<std::vector<double>()> {
        if (!in.paired_passes) return {};
        return [&in, kind, &rays] { return in.paired_passes(kind, rays); };
    };
    res.primary = timed_launches(ctx, kPrimaryEntry, primary.size(), in.repeat, res.timing,
                                 res.primary_variant, paired_on(RayKind::kPrimary, primary),
                                 primary_ratios, res.trees_upgraded);
    res.paired.resize(primary_ratios.size());
    for (size_t e = 0; e < res.paired.size(); ++e) res.paired[e].primary = primary_ratios[e];
    const std::vector<programs::RayHit> hit =
        in_ray_order(primary_hits->data<programs::RayHit>(), primary_order);
    sum_hits(hit, res.primary_hits, res.primary_sum_t);
    std::vector<float> t(primary.size());
    std::vector<unsigned> prim(primary.size());
    for (size_t i = 0; i < primary.size(); ++i) t[i] = hit[i].t, prim[i] = hit[i].prim;
    RaySet shadow, diffuse;
    secondary_rays(primary, t.data(), prim.data(), mesh, in.light, shadow, diffuse);
    res.shadow_rays = shadow.size();
    res.diffuse_rays = diffuse.size();
    if (shadow.size() == 0) return res;  // no primary hit: nothing more to trace

    const std::vector<uint32_t> shadow_order = launch_order(shadow, in);
    auto shadow_program = program_for(ctx, shadow_entry, shadow, shadow_order);
    auto blocked = ctx.create_buffer<unsigned char>(BufferType::kOutput, unsigned(shadow.size()));
    (*shadow_program)["blocked"] = blocked;
    ctx.set_entry_point_count(2);
    ctx.set_ray_generation_program(kShadowEntry, shadow_program);
    res.shadow =
        timed_launches(ctx, kShadowEntry, shadow.size(), in.repeat, res.timing, res.shadow_variant,
                       paired_on(RayKind::kShadow, shadow), shadow_ratios, res.trees_upgraded);
    const unsigned char* b = blocked->data<unsigned char>();
    for (size_t i = 0; i < shadow.size(); ++i) res.occluded += b[i];

    const std::vector<uint32_t> diffuse_order = launch_order(diffuse, in);
    auto diffuse_program = program_for(ctx, closest_entry, diffuse, diffuse_order);
    auto diffuse_hits = closest_outputs(*diffuse_program, diffuse.size());
    ctx.set_entry_point_count(3);
    ctx.set_ray_generation_program(kDiffuseEntry, diffuse_program);
    res.diffuse = timed_launches(ctx, kDiffuseEntry, diffuse.size(), in.repeat, res.timing,
                                 res.diffuse_variant, paired_on(RayKind::kDiffuse, diffuse),
                                 diffuse_ratios, res.trees_upgraded);
    for (size_t e = 0; e < res.paired.size(); ++e) {
        res.paired[e].shadow = e < shadow_ratios.size() ? shadow_ratios[e] : 0.0;
        res.paired[e].diffuse = e < diffuse_ratios.size() ? diffuse_ratios[e] : 0.0;
    }
    sum_hits(in_ray_order(diffuse_hits->data<programs::RayHit>(), diffuse_order), res.diffuse_hits,
             res.diffuse_sum_t);
    return res;
}

}  // namespace lucent::bench

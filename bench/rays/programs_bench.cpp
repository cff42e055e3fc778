#include "bench/rays/programs_bench.h"

#include <cstdlib>
#include <functional>
#include <vector>

#include "bench/common/input_buffer.h"
#include "bench/rays/rays_programs.h"
#include "lucent/lucent.h"
#include "samples/stages.h"

namespace lucent::bench {

namespace {

namespace programs = lucent_bench_rays;

constexpr unsigned kPrimaryEntry = 0, kShadowEntry = 1, kDiffuseEntry = 2;

/// A ray-generation program with its own ray set bound to it (its own variable scope), two
/// float4s a ray: (origin, tmin), (direction, tmax).
std::shared_ptr<Program> program_for(Context& ctx, const char* name, const RaySet& rays) {
    std::vector<float4> packed(2 * rays.size());
    for (size_t i = 0; i < rays.size(); ++i) {
        const float3 o = rays.origin[i], d = rays.direction[i];
        packed[2 * i] = float4{o.x, o.y, o.z, 0.0f};  // BENCH.md: tmin is 0 for every ray
        packed[2 * i + 1] = float4{d.x, d.y, d.z, rays.tmax[i]};
    }
    auto program = ctx.create_program(name);
    (*program)["rays"] = input_buffer(ctx, packed);
    return program;
}

/// The kernel variant a CUDA launch ran (empty on the CPU): as compiled, or compiled with
/// registers capped, trace() inlined or both (ContextOptions::register_variants).
std::string variant_of(const LaunchReport& report) {
    if (report.kernel_ms <= 0) return "";
    const std::string cap = "registers capped to " + std::to_string(report.register_cap);
    if (report.trace_inlined && report.registers_capped) return "trace inlined, " + cap;
    if (report.trace_inlined) return "trace inlined";
    if (report.registers_capped) return cap;
    return "as compiled";
}

/// Mrays/s of `repeat` launches of `entry` over `count` rays, all after the tuning: the
/// first launch compiles the scene and, on the GPU, the kernel; trial launches are left out
/// as the samples' `render --repeat` leaves them (samples::SteadyLaunches), so a median of
/// 5 is never a trial shape's time.
/// With `paired` (a set's PairedPasses bound to its rays), each timed launch also has the
/// paired engines' passes beside it, in turn before and after it; `ratios[e]` gets the
/// median of engine e's pass seconds over its neighbouring launch's.
Rate timed_launches(Context& ctx, unsigned entry, size_t count, int repeat, std::string& timing,
                    std::string& variant, const std::function<std::vector<double>()>& paired,
                    std::vector<double>& ratios) {
    samples::SteadyLaunches steady;
    ctx.launch(entry, unsigned(count));
    if (paired) paired();  // their warm-up pass, as the launch above is the programs'
    std::vector<std::vector<double>> pair_ratios;
    const int most = repeat + int(samples::kMostTrialLaunches);
    for (int launch = 1; launch < most && int(steady.ms.size()) < repeat; ++launch) {
        const bool paired_first = paired && launch % 2 == 0;
        std::vector<double> passes;
        if (paired_first) passes = paired();
        ctx.launch(entry, unsigned(count));
        const LaunchReport& report = ctx.last_launch();
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
    auto sum_hits = [](const programs::RayHit* hit, size_t count, size_t& hits, double& sum_t) {
        for (size_t i = 0; i < count; ++i)
            if (hit[i].t >= 0.0f) ++hits, sum_t += hit[i].t;
    };

    // Primary rays, then the shadow and diffuse sets from their hits (BENCH.md).
    auto primary_program = program_for(ctx, "closest_rays", primary);
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
                                 primary_ratios);
    res.paired.resize(primary_ratios.size());
    for (size_t e = 0; e < res.paired.size(); ++e) res.paired[e].primary = primary_ratios[e];
    const auto* hit = primary_hits->data<programs::RayHit>();
    sum_hits(hit, primary.size(), res.primary_hits, res.primary_sum_t);
    std::vector<float> t(primary.size());
    std::vector<unsigned> prim(primary.size());
    for (size_t i = 0; i < primary.size(); ++i) t[i] = hit[i].t, prim[i] = hit[i].prim;
    RaySet shadow, diffuse;
    secondary_rays(primary, t.data(), prim.data(), mesh, in.light, shadow, diffuse);
    res.shadow_rays = shadow.size();
    res.diffuse_rays = diffuse.size();
    if (shadow.size() == 0) return res;  // no primary hit: nothing more to trace

    auto shadow_program = program_for(ctx, "shadow_rays", shadow);
    auto blocked = ctx.create_buffer<unsigned char>(BufferType::kOutput, unsigned(shadow.size()));
    (*shadow_program)["blocked"] = blocked;
    ctx.set_entry_point_count(2);
    ctx.set_ray_generation_program(kShadowEntry, shadow_program);
    res.shadow = timed_launches(ctx, kShadowEntry, shadow.size(), in.repeat, res.timing,
                                res.shadow_variant, paired_on(RayKind::kShadow, shadow),
                                shadow_ratios);
    const unsigned char* b = blocked->data<unsigned char>();
    for (size_t i = 0; i < shadow.size(); ++i) res.occluded += b[i];

    auto diffuse_program = program_for(ctx, "closest_rays", diffuse);
    auto diffuse_hits = closest_outputs(*diffuse_program, diffuse.size());
    ctx.set_entry_point_count(3);
    ctx.set_ray_generation_program(kDiffuseEntry, diffuse_program);
    res.diffuse = timed_launches(ctx, kDiffuseEntry, diffuse.size(), in.repeat, res.timing,
                                 res.diffuse_variant, paired_on(RayKind::kDiffuse, diffuse),
                                 diffuse_ratios);
    for (size_t e = 0; e < res.paired.size(); ++e) {
        res.paired[e].shadow = e < shadow_ratios.size() ? shadow_ratios[e] : 0.0;
        res.paired[e].diffuse = e < diffuse_ratios.size() ? diffuse_ratios[e] : 0.0;
    }
    sum_hits(diffuse_hits->data<programs::RayHit>(), diffuse.size(), res.diffuse_hits,
             res.diffuse_sum_t);
    return res;
}

}  // namespace lucent::bench

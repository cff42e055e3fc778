// A procedural head of hair (scene/hair_strands.h: strands rooted on the upper part of a
// unit sphere, bending under gravity, tapering); the head itself is a built-in sphere in the
// same group. Primary rays (entry 0) and one diffuse ray from each primary hit (entry 1) are
// launched alternately after warm-ups, timed per launch (CUDA events on the GPU, the launch
// on the CPU) after the launch-shape tuning (trial launches left out, as render --repeat):
// Mrays/s as median and spread.
#include "bench/curves/curves_bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "bench/common/input_buffer.h"
#include "bench/common/option_checks.h"
#include "bench/common/rate.h"
#include "bench/common/report.h"
#include "bench/curves/curves_programs.h"
#include "lucent/error.h"
#include "lucent/lucent.h"
#include "samples/stages.h"
#include "scene/hair_strands.h"

namespace lucent::bench {

namespace {

namespace programs = lucent_bench_curves;

const char* type_name(CurveType type) {
    switch (type) {
        case kCurveLinear: return "linear";
        case kCurveQuadraticBSpline: return "quadratic B-spline";
        case kCurveCubicBSpline: return "cubic B-spline";
        default: return "Catmull-Rom";
    }
}

void check_options(const CurvesBenchOptions& options) {
    require_in_range("bench curves", "segments (--segments)", options.segments, 1, 16777216);
    require_in_range("bench curves", "repeat (--repeat)", options.repeat, 1, 1000);
    require_in_range("bench curves", "threads (--threads)", options.threads, 0, 4096);
    require_image_size("bench curves", options.width, options.height);
}

}  // namespace

std::string bench_curves_json(CurvesBenchOptions options) {
    return captured_document("bench curves", std::move(options), run_curves_bench);
}

int run_curves_bench(const CurvesBenchOptions& options) {
    check_options(options);
    scene::HairStyle style;  // the unit head at the origin
    style.segments = options.segments;
    style.type = options.type;
    const scene::HairStrands hair = scene::make_hair_strands(style);
    ContextOptions context_options;
    context_options.backend = options.backend;
    context_options.threads = options.threads;
    Context ctx(context_options);
    ctx.add_module("lucent_bench_curves");
    ctx.set_entry_point_count(2);
    ctx.set_ray_type<programs::HairHit>(programs::kBenchRay, "bench");
    ctx.set_miss_program(programs::kBenchRay, ctx.create_program("hair_miss"));
    ctx.set_ray_generation_program(0, ctx.create_program("hair_primary_rays"));
    ctx.set_ray_generation_program(1, ctx.create_program("hair_diffuse_rays"));

    auto strands = ctx.create_geometry_curves();
    strands->set_curve_type(options.type);
    strands->set_vertices(input_buffer(ctx, hair.vertices));
    strands->set_radii(input_buffer(ctx, hair.radii));
    strands->set_segment_indices(input_buffer(ctx, hair.segments));
    auto strand_material = ctx.create_material();
    strand_material->set_closest_hit(programs::kBenchRay, ctx.create_program("hair_strand_hit"));
    auto head = ctx.create_geometry_spheres();
    head->set_centers(input_buffer(ctx, std::vector<float3>{make_float3(0.0f)}));
    head->set_radii(input_buffer(ctx, std::vector<float>{1.0f}));
    auto head_material = ctx.create_material();
    head_material->set_closest_hit(programs::kBenchRay, ctx.create_program("hair_head_hit"));
    auto group = ctx.create_geometry_group();
    for (auto [geometry, material] : {std::pair<std::shared_ptr<GeometryBase>,
                                                std::shared_ptr<Material>>{strands, strand_material},
                                      {head, head_material}}) {
        auto instance = ctx.create_geometry_instance();
        instance->set_geometry(geometry);
        instance->add_material(material);
        group->add_child(instance);
    }

    // A pinhole 3.4 in front of the head, 40° vertical field of view.
    const float tan_half = std::tan(0.5f * 40.0f * 3.14159265f / 180.0f);
    const float aspect = float(options.width) / float(options.height);
    const unsigned pixels = options.width * options.height;
    auto points = ctx.create_buffer<float4>(BufferType::kInputOutput, pixels);
    auto normals = ctx.create_buffer<float4>(BufferType::kInputOutput, pixels);
    auto diffuse_hits = ctx.create_buffer<unsigned>(BufferType::kOutput, pixels);
    ctx["scene"] = group;
    ctx["eye"] = make_float3(0.0f, 0.1f, -3.4f);
    ctx["u"] = make_float3(aspect * tan_half, 0.0f, 0.0f);
    ctx["v"] = make_float3(0.0f, tan_half, 0.0f);
    ctx["w"] = make_float3(0.0f, 0.0f, 1.0f);
    ctx["offset"] = 2e-5f;
    ctx["seed"] = 1u;
    ctx["points"] = points;
    ctx["normals"] = normals;
    ctx["diffuse_hits"] = diffuse_hits;

    std::string timing;
    for (int i = 0; i < 4; ++i) {  // compile, build, the GPU's launch-shape trials
        ctx.launch(0, options.width, options.height);
        ctx.launch(1, options.width, options.height);
    }
    unsigned primary_hits = 0;
    for (unsigned i = 0; i < pixels; ++i) primary_hits += points->data<float4>()[i].w != 0.0f;
    // Each entry's launches after its launch-shape tuning, as render --repeat counts them
    // (samples::SteadyLaunches leaves out trial launches, and the launches before a late one).
    samples::SteadyLaunches primary_launches, diffuse_launches;
    const size_t repeat = size_t(options.repeat);
    const int most = options.repeat + int(samples::kMostTrialLaunches);
    for (int run = 0; run < most && (primary_launches.ms.size() < repeat ||
                                     diffuse_launches.ms.size() < repeat);
         ++run) {
        ctx["seed"] = unsigned(run + 2);
        ctx.launch(0, options.width, options.height);
        primary_launches.add(ctx.last_launch());
        ctx.launch(1, options.width, options.height);
        diffuse_launches.add(ctx.last_launch());
    }
    if (primary_launches.ms.empty() || diffuse_launches.ms.empty())
        throw Error("bench curves: the launch-shape tuning was still trying shapes after " +
                    std::to_string(most) + " launches of each entry; no steady launch to time");
    const auto rates = [&](const samples::SteadyLaunches& launches, double rays) {
        std::vector<double> out;
        for (size_t i = 0; i < launches.ms.size() && out.size() < repeat; ++i)
            out.push_back(
                samples::launch_mrays(rays, launches.kernel_ms[i], launches.ms[i], timing));
        return out;
    };
    const std::vector<double> primary = rates(primary_launches, pixels),
                              diffuse = rates(diffuse_launches, primary_hits);
    const unsigned trials = primary_launches.trials + diffuse_launches.trials;
    unsigned diffuse_hit_count = 0;
    for (unsigned i = 0; i < pixels; ++i) diffuse_hit_count += diffuse_hits->data<unsigned>()[i];
    const Rate primary_rate = rate_of(primary), diffuse_rate = rate_of(diffuse);
    const std::string backend = ctx.backend_name();
    if (options.json) {
        print_json(Json{{"benchmark", "curves"},
                        {"backend", backend},
                        {"curve_type", type_name(options.type)},
                        {"segments", unsigned(hair.segments.size())},
                        {"width", options.width},
                        {"height", options.height},
                        {"timing", timing},
                        {"primary_hit_fraction", rounded(double(primary_hits) / pixels, 4)},
                        {"diffuse_hit_fraction",
                         rounded(primary_hits ? double(diffuse_hit_count) / primary_hits : 0, 4)},
                        {"primary_mrays", rate_json(primary_rate)},
                        {"diffuse_mrays", rate_json(diffuse_rate)},
                        {"launch_shape_trials_left_out", trials}});
    } else {
        std::printf("curves: %zu %s segments of hair on a sphere, %ux%u on %s (%s time)\n",
                    hair.segments.size(), type_name(options.type), options.width,
                    options.height, backend.c_str(), timing.c_str());
        std::printf("  primary rays  %s, %.1f %% hit\n", rate_text(primary_rate).c_str(),
                    100.0 * primary_hits / pixels);
        std::printf("  diffuse rays  %s (one per primary hit), %.1f %% hit\n",
                    rate_text(diffuse_rate).c_str(),
                    primary_hits ? 100.0 * diffuse_hit_count / primary_hits : 0.0);
        if (trials > 0)
            std::printf("  (after %u launch-shape trial launches, left out)\n", trials);
    }
    return 0;
}

}  // namespace lucent::bench

// A procedural head of hair: strands rooted on the upper part of a unit sphere, each a
// chain of control points that leaves along the surface normal and bends under gravity
// with a little noise, radius tapering from root to tip; the head itself is a built-in
// sphere in the same group. Primary rays (entry 0) and one diffuse ray from each primary
// hit (entry 1) are launched alternately after warm-ups, timed per launch (CUDA events on
// the GPU, the launch on the CPU): Mrays/s as median and spread.
#include "bench/curves/curves_bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "bench/common/input_buffer.h"
#include "bench/common/rate.h"
#include "bench/common/report.h"
#include "bench/curves/curves_programs.h"
#include "lucent/lucent.h"

namespace lucent::bench {

namespace {

namespace programs = lucent_bench_curves;

constexpr unsigned kSegmentsPerStrand = 12;

const char* type_name(CurveType type) {
    switch (type) {
        case kCurveLinear: return "linear";
        case kCurveQuadraticBSpline: return "quadratic B-spline";
        case kCurveCubicBSpline: return "cubic B-spline";
        default: return "Catmull-Rom";
    }
}

struct Hair {
    std::vector<float3> vertices;
    std::vector<float> radii;
    std::vector<unsigned> segments;
};

Hair make_hair(unsigned segment_count, CurveType type) {
    Hair hair;
    const unsigned points_per_segment = curve_control_points(type);
    // Consecutive segments of a strand share all but one control point.
    const unsigned extra = points_per_segment - 1;
    const unsigned strands = std::max(1u, (segment_count + kSegmentsPerStrand - 1) / kSegmentsPerStrand);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f), jitter(-1.0f, 1.0f);
    const float step = 0.07f;
    for (unsigned s = 0; s < strands && hair.segments.size() < segment_count; ++s) {
        // A root on the sphere above y = -0.3, uniform in area.
        const float y = -0.3f + 1.3f * unit(rng), phi = 6.2831853f * unit(rng);
        const float ring = std::sqrt(std::max(0.0f, 1.0f - y * y));
        float3 p = make_float3(ring * std::cos(phi), y, ring * std::sin(phi));
        float3 dir = p;
        const unsigned first = unsigned(hair.vertices.size());
        const unsigned points = kSegmentsPerStrand + extra;
        for (unsigned k = 0; k < points; ++k) {
            hair.vertices.push_back(p * 1.002f);
            const float along = float(k) / float(points - 1);
            hair.radii.push_back(0.004f * (1.0f - 0.75f * along));
            dir = normalize(dir + make_float3(0.0f, -0.35f, 0.0f) +
                            0.25f * make_float3(jitter(rng), jitter(rng), jitter(rng)));
            p = p + step * dir;
        }
        for (unsigned k = 0; k < kSegmentsPerStrand && hair.segments.size() < segment_count; ++k)
            hair.segments.push_back(first + k);
    }
    return hair;
}

double mrays(const LaunchReport& report, double rays, std::string& timing) {
    const bool kernel = report.kernel_ms > 0;
    timing = kernel ? "kernel" : "launch";
    const double ms = kernel ? report.kernel_ms : report.launch_ms;
    return ms > 0 ? rays / (ms * 1e3) : 0.0;
}

}  // namespace

int run_curves_bench(const CurvesBenchOptions& options) {
    const Hair hair = make_hair(options.segments, options.type);
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
    std::vector<double> primary, diffuse;
    for (int run = 0; run < options.repeat; ++run) {
        ctx["seed"] = unsigned(run + 2);
        ctx.launch(0, options.width, options.height);
        primary.push_back(mrays(ctx.last_launch(), pixels, timing));
        ctx.launch(1, options.width, options.height);
        diffuse.push_back(mrays(ctx.last_launch(), primary_hits, timing));
    }
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
                        {"diffuse_mrays", rate_json(diffuse_rate)}});
    } else {
        std::printf("curves: %zu %s segments of hair on a sphere, %ux%u on %s (%s time)\n",
                    hair.segments.size(), type_name(options.type), options.width,
                    options.height, backend.c_str(), timing.c_str());
        std::printf("  primary rays  %s, %.1f %% hit\n", rate_text(primary_rate).c_str(),
                    100.0 * primary_hits / pixels);
        std::printf("  diffuse rays  %s (one per primary hit), %.1f %% hit\n",
                    rate_text(diffuse_rate).c_str(),
                    primary_hits ? 100.0 * diffuse_hit_count / primary_hits : 0.0);
    }
    return 0;
}

}  // namespace lucent::bench

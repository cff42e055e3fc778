// Built-in spheres against the same spheres as a custom primitive: two Contexts on one
// backend, each with the field as its scene, launched alternately (A B, B A, ...) after a
// warm-up each, timed per launch (CUDA events on the GPU, the launch on the CPU) and after
// the launch-shape tuning (trial launches left out, as render --repeat); Mrays/s as
// median and spread, and the ratio as the median of neighbouring launches' ratios. Both
// must give every pixel the same sphere: the figure is of the same work.
#include "bench/spheres/spheres_bench.h"

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "bench/common/input_buffer.h"
#include "bench/common/option_checks.h"
#include "bench/common/rate.h"
#include "bench/common/report.h"
#include "bench/spheres/spheres_programs.h"
#include "lucent/error.h"
#include "lucent/lucent.h"
#include "samples/stages.h"

namespace lucent::bench {

namespace {

namespace programs = lucent_bench_spheres;

/// A cube [-1, 1]³ of spheres with radii around 0.6 / cbrt(count) (about a tenth of the
/// cube's volume, so that primary rays pass several spheres' boxes before their hit).
struct SphereField {
    std::vector<float3> centers;
    std::vector<float> radii;
};
SphereField make_field(unsigned count) {
    SphereField f;
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> position(-1.0f, 1.0f), scale(0.5f, 1.5f);
    const float radius = 0.6f / std::cbrt(float(count));
    for (unsigned i = 0; i < count; ++i) {
        f.centers.push_back(make_float3(position(rng), position(rng), position(rng)));
        f.radii.push_back(radius * scale(rng));
    }
    return f;
}

/// One path's Context: the camera's ray generation over `field` as built-in or custom spheres.
struct SpherePath {
    std::unique_ptr<Context> ctx;
    std::shared_ptr<Buffer> t, prim;
};

SpherePath make_path(const SpheresBenchOptions& options, const SphereField& field, bool builtin) {
    ContextOptions context_options;
    context_options.backend = options.backend;
    context_options.threads = options.threads;
    SpherePath path;
    path.ctx = std::make_unique<Context>(context_options);
    Context& ctx = *path.ctx;
    ctx.add_module("lucent_bench_spheres");
    ctx.set_entry_point_count(1);
    ctx.set_ray_type<programs::SphereHit>(programs::kBenchRay, "bench");
    ctx.set_miss_program(programs::kBenchRay, ctx.create_program("sphere_miss"));
    ctx.set_ray_generation_program(0, ctx.create_program("sphere_primary_rays"));
    std::shared_ptr<GeometryBase> geometry;
    auto material = ctx.create_material();
    auto centers = input_buffer(ctx, field.centers);
    auto radii = input_buffer(ctx, field.radii);
    if (builtin) {
        auto spheres = ctx.create_geometry_spheres();
        spheres->set_centers(centers);
        spheres->set_radii(radii);
        geometry = spheres;
        material->set_closest_hit(programs::kBenchRay, ctx.create_program("builtin_sphere_hit"));
    } else {
        auto custom = ctx.create_geometry();
        custom->set_primitive_count(unsigned(field.centers.size()));
        custom->set_bounding_box_program(ctx.create_program("custom_sphere_bounds"));
        custom->set_intersection_program(ctx.create_program("custom_sphere_intersect"));
        (*custom)["centers"] = centers;
        (*custom)["radii"] = radii;
        geometry = custom;
        material->set_closest_hit(programs::kBenchRay, ctx.create_program("custom_sphere_hit"));
    }
    auto instance = ctx.create_geometry_instance();
    instance->set_geometry(geometry);
    instance->add_material(material);
    auto group = ctx.create_geometry_group();
    group->add_child(instance);
    // A pinhole 3.2 in front of the cube, 45° vertical field of view.
    const float tan_half = std::tan(0.5f * 45.0f * 3.14159265f / 180.0f);
    const float aspect = float(options.width) / float(options.height);
    const unsigned pixels = options.width * options.height;
    path.t = ctx.create_buffer<float>(BufferType::kOutput, pixels);
    path.prim = ctx.create_buffer<unsigned>(BufferType::kOutput, pixels);
    ctx["scene"] = group;
    ctx["eye"] = make_float3(0.0f, 0.0f, -3.2f);
    ctx["u"] = make_float3(aspect * tan_half, 0.0f, 0.0f);
    ctx["v"] = make_float3(0.0f, tan_half, 0.0f);
    ctx["w"] = make_float3(0.0f, 0.0f, 1.0f);
    ctx["t"] = path.t;
    ctx["prim"] = path.prim;
    return path;
}

/// One launch of `path`: its Mrays/s, and whether it was a launch-shape trial.
struct PathLaunch {
    double mrays;
    bool trial;
};
PathLaunch timed_launch(SpherePath& path, const SpheresBenchOptions& options,
                        std::string& timing) {
    path.ctx->launch(0, options.width, options.height);
    const LaunchReport& report = path.ctx->last_launch();
    return {samples::launch_mrays(double(options.width) * options.height, report.kernel_ms,
                                  report.launch_ms, timing),
            report.launch_shape_trial};
}

void check_options(const SpheresBenchOptions& options) {
    require_in_range("bench spheres", "count (--count)", options.count, 1, 16777216);
    require_in_range("bench spheres", "repeat (--repeat)", options.repeat, 1, 1000);
    require_in_range("bench spheres", "threads (--threads)", options.threads, 0, 4096);
    require_image_size("bench spheres", options.width, options.height);
}

}  // namespace

std::string bench_spheres_json(SpheresBenchOptions options) {
    return captured_document("bench spheres", std::move(options), run_spheres_bench);
}

int run_spheres_bench(const SpheresBenchOptions& options) {
    check_options(options);
    const SphereField field = make_field(options.count);
    SpherePath builtin = make_path(options, field, true);
    SpherePath custom = make_path(options, field, false);
    std::string timing;
    // Warm-ups: compile, accel build, the GPU's megakernel and most of its launch-shape
    // tuning (the timed loop below leaves out any trial launch still to come).
    for (int i = 0; i < 6; ++i) {
        timed_launch(builtin, options, timing);
        timed_launch(custom, options, timing);
    }
    // Pairs of launches after the launch-shape tuning, as render --repeat counts them
    // (samples::SteadyLaunches): a pair with a trial launch in it (a shape or a kernel
    // variant being tried, not the one chosen; variants arrive from a background compile)
    // is left out, with the pairs before it, since the choice may change.
    std::vector<double> a, b, ratios;
    unsigned trials = 0;
    const int most = options.repeat + int(samples::kMostTrialLaunches);
    for (int run = 0; int(a.size()) < options.repeat && run < most; ++run) {
        PathLaunch x, y;
        if (run % 2 == 0) {
            x = timed_launch(builtin, options, timing);
            y = timed_launch(custom, options, timing);
        } else {
            y = timed_launch(custom, options, timing);
            x = timed_launch(builtin, options, timing);
        }
        if (x.trial || y.trial) {
            trials += unsigned(x.trial) + unsigned(y.trial);
            a.clear(), b.clear(), ratios.clear();
            continue;
        }
        a.push_back(x.mrays);
        b.push_back(y.mrays);
        ratios.push_back(y.mrays > 0 ? x.mrays / y.mrays : 0.0);
    }
    if (a.empty())
        throw Error("bench spheres: the launch-shape tuning was still trying shapes after " +
                    std::to_string(most) + " pairs of launches; no steady launch to time");
    // The same work: every pixel the same sphere (or none), t to float rounding.
    const unsigned* pa = builtin.prim->data<unsigned>();
    const unsigned* pb = custom.prim->data<unsigned>();
    const unsigned pixels = options.width * options.height;
    unsigned differ = 0, hits = 0;
    for (unsigned i = 0; i < pixels; ++i) {
        differ += pa[i] != pb[i];
        hits += pa[i] != ~0u;
    }
    const Rate builtin_rate = rate_of(a), custom_rate = rate_of(b);
    const double ratio = median_of(ratios);
    const std::string backend = builtin.ctx->backend_name();
    if (options.json) {
        print_json(Json{{"benchmark", "spheres"},
                        {"backend", backend},
                        {"spheres", options.count},
                        {"width", options.width},
                        {"height", options.height},
                        {"timing", timing},
                        {"hit_fraction", rounded(double(hits) / pixels, 4)},
                        {"pixels_that_differ", differ},
                        {"builtin_mrays", rate_json(builtin_rate)},
                        {"custom_mrays", rate_json(custom_rate)},
                        {"builtin_over_custom", rounded(ratio, 3)},
                        {"launch_shape_trials_left_out", trials}});
    } else {
        std::printf("spheres: %u in [-1,1]^3, primary rays %ux%u on %s (%s time), %.1f %% hit\n",
                    options.count, options.width, options.height, backend.c_str(),
                    timing.c_str(), 100.0 * hits / pixels);
        std::printf("  built-in spheres       %s\n", rate_text(builtin_rate).c_str());
        std::printf("  custom program spheres %s\n", rate_text(custom_rate).c_str());
        std::printf("  built-in / custom      %.3f (median of paired launches)\n", ratio);
        if (trials > 0)
            std::printf("  (after %u launch-shape trial launches, left out)\n", trials);
        std::printf("  pixels whose sphere differs: %u of %u\n", differ, pixels);
    }
    if (differ > pixels / 10000)
        throw Error("bench spheres: the built-in and the custom-program spheres disagree on " +
                    std::to_string(differ) + " of " + std::to_string(pixels) +
                    " pixels; the figures are not of the same work");
    return 0;
}

}  // namespace lucent::bench

// The first program (examples/first-program) launched across the processes of an MPI job:
// every rank runs this same program, ContextOptions::ranks spreads the launch over them, and
// every rank's output buffer holds the whole image; rank 0 alone prints and writes it
// (docs/distributed.md).
//
//   mpirun -np 3 across-ranks [--backend cpu|cuda|auto] [--jit-check SM] [--out FILE.png]
//
// Without mpirun the group is this process alone, and the image the same.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "first_program.h"
#include "lucent/lucent.h"
#include "scene/image_io.h"

// The flags every example takes; false (after saying why) on a bad one.
static bool parse_args(int argc, char** argv, lucent::ContextOptions& options, std::string& out) {
    using lucent::BackendKind;
    for (int i = 1; i < argc; i += 2) {
        const std::string flag = argv[i], value = i + 1 < argc ? argv[i + 1] : "";
        if (flag == "--backend" && (value == "cpu" || value == "cuda" || value == "auto")) {
            options.backend = value == "cpu"    ? BackendKind::kCpu
                              : value == "cuda" ? BackendKind::kCuda
                                                : BackendKind::kAuto;
        } else if (flag == "--jit-check" && std::atoi(value.c_str()) > 0) {
            options.jit_check_sm = std::atoi(value.c_str());  // e.g. 90: sm_90
        } else if (flag == "--out" && !value.empty()) {
            out = value;
        } else {
            std::fprintf(stderr,
                         "across-ranks: bad argument '%s %s'\nusage: across-ranks "
                         "[--backend cpu|cuda|auto] [--jit-check SM] [--out FILE.png]\n",
                         flag.c_str(), value.c_str());
            return false;
        }
    }
    return true;
}

int main(int argc, char** argv) {
    lucent::ContextOptions options;
    std::string out = "across-ranks.png";
    if (!parse_args(argc, argv, options, out)) return 2;
    int rank = 0;
    try {
        options.ranks = lucent::Ranks::world();  // every rank: initialises MPI under mpirun
        rank = options.ranks->rank();
        const std::shared_ptr<lucent::Ranks>& ranks = options.ranks;

        // The same host code on every rank: each launch checks that it is (its digest). A
        // rank that fails while building (a file missing on its node) tells the others in
        // lucent::run_agreed instead of leaving them waiting in the launch.
        const unsigned width = 640, height = 480;
        std::unique_ptr<lucent::Context> ctx;
        std::shared_ptr<lucent::Buffer> image;
        lucent::run_agreed(ranks, [&] {
            ctx = std::make_unique<lucent::Context>(options);
            ctx->set_ray_type<first_program::Payload>(0, "radiance");
            ctx->set_ray_generation_program(
                0, ctx->create_program(LUCENT_PROGRAM(first_program::camera)));
            ctx->set_miss_program(0,
                                  ctx->create_program(LUCENT_PROGRAM(first_program::background)));
            auto vertices = ctx->create_buffer<float3>(lucent::BufferType::kInput, 3);
            vertices->upload(std::vector<float3>{{-1, -1, -2}, {1, -1, -2.5f}, {0, 1, -1.5f}});
            auto triangle = ctx->create_geometry_triangles();
            triangle->set_vertices(vertices);
            auto material = ctx->create_material();
            material->set_closest_hit(0, ctx->create_program(LUCENT_PROGRAM(first_program::shade)));
            (*material)["color"] = make_float3(1, 0.5f, 0.2f);
            auto instance = ctx->create_geometry_instance();
            instance->set_geometry(triangle);
            instance->add_material(material);
            auto scene = ctx->create_geometry_group();
            scene->add_child(instance);
            image = ctx->create_buffer<float3>(lucent::BufferType::kOutput, width, height);
            (*ctx)["eye"] = make_float3(0, 0, 0);
            (*ctx)["scene"] = scene;
            (*ctx)["image"] = image;
            ctx->launch(0, width, height);  // its rows spread over every rank's devices
        });

        // Every rank holds the whole image now; rank 0 writes it, and every rank learns
        // whether it could, so all exit alike.
        const float3* pixels = image->data<float3>();
        const lucent::scene::Image png{width, height, {pixels, pixels + width * height}};
        lucent::run_agreed(ranks, [&] {
            if (rank == 0) lucent::scene::write_image(out, png);
        });
        if (rank != 0) return 0;

        const auto lit = std::count_if(png.pixels.begin(), png.pixels.end(),
                                       [](float3 c) { return c.x > 0.2f; });
        std::printf("backend: %s\n", ctx->backend_name().c_str());  // "3 ranks, rank 0 on cpu"
        if (options.jit_check_sm)
            std::printf("jit-check: megakernel compiled for sm_%d in %.0f ms%s\n",
                        options.jit_check_sm, ctx->last_launch().jit_ms,
                        ctx->last_launch().jit_cached ? " (from the cache)" : "");
        // Empty with one rank: the launch ran whole.
        const auto& shares = ctx->last_launch().ranks;
        for (size_t r = 0; r < shares.size(); ++r)
            std::printf("rank %zu: %llu pixels in %u pieces\n", r,
                        (unsigned long long)shares[r].indices, shares[r].pieces);
        std::printf("the triangle covers %ld of %u pixels\n", long(lit), width * height);
        std::printf("wrote %s (%ux%u)\n", out.c_str(), width, height);
    } catch (const lucent::RankError& e) {
        if (rank == 0) std::fprintf(stderr, "across-ranks: %s\n", e.what());  // every rank has it
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "across-ranks: rank %d: %s\n", rank, e.what());
        return 1;
    }
    return 0;
}

// The first program of docs/programming-model.md: one triangle in front of a pinhole
// camera, shaded by the angle between its normal and each ray, written to a PNG.
//
//   first-program [--backend cpu|cuda|auto] [--jit-check SM] [--out FILE.png]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
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
                         "first-program: bad argument '%s %s'\nusage: first-program "
                         "[--backend cpu|cuda|auto] [--jit-check SM] [--out FILE.png]\n",
                         flag.c_str(), value.c_str());
            return false;
        }
    }
    return true;
}

int main(int argc, char** argv) {
    lucent::ContextOptions options;
    std::string out = "first-program.png";
    if (!parse_args(argc, argv, options, out)) return 2;
    try {
        lucent::Context ctx(options);
        ctx.set_ray_type<first_program::Payload>(0, "radiance");  // ray type 0 and its payload
        auto camera = ctx.create_program(LUCENT_PROGRAM(first_program::camera));
        ctx.set_ray_generation_program(0, camera);  // entry point 0
        ctx.set_miss_program(0, ctx.create_program(LUCENT_PROGRAM(first_program::background)));

        // The scene: one triangle, in one geometry instance with one material.
        auto vertices = ctx.create_buffer<float3>(lucent::BufferType::kInput, 3);
        vertices->upload(std::vector<float3>{{-1, -1, -2}, {1, -1, -2.5f}, {0, 1, -1.5f}});
        auto triangle = ctx.create_geometry_triangles();
        triangle->set_vertices(vertices);
        auto material = ctx.create_material();
        material->set_closest_hit(0, ctx.create_program(LUCENT_PROGRAM(first_program::shade)));
        (*material)["color"] = make_float3(1, 0.5f, 0.2f);
        auto instance = ctx.create_geometry_instance();
        instance->set_geometry(triangle);
        instance->add_material(material);
        auto scene = ctx.create_geometry_group();
        scene->add_child(instance);

        // The camera's variables, set on the context, and the launch: one index per pixel.
        const unsigned width = 640, height = 480;
        auto image = ctx.create_buffer<float3>(lucent::BufferType::kOutput, width, height);
        ctx["eye"] = make_float3(0, 0, 0);
        ctx["scene"] = scene;  // a node becomes a Handle
        ctx["image"] = image;
        ctx.launch(0, width, height);

        const float3* pixels = image->data<float3>();
        const lucent::scene::Image png{width, height, {pixels, pixels + width * height}};
        lucent::scene::write_image(out, png);
        const auto lit = std::count_if(png.pixels.begin(), png.pixels.end(),
                                       [](float3 c) { return c.x > 0.2f; });  // not background

        std::printf("backend: %s\n", ctx.backend_name().c_str());
        if (options.jit_check_sm)
            std::printf("jit-check: megakernel compiled for sm_%d in %.0f ms%s\n",
                        options.jit_check_sm, ctx.last_launch().jit_ms,
                        ctx.last_launch().jit_cached ? " (from the cache)" : "");
        std::printf("the triangle covers %ld of %u pixels\n", long(lit), width * height);
        std::printf("wrote %s (%ux%u)\n", out.c_str(), width, height);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "first-program: %s\n", e.what());
        return 1;
    }
    return 0;
}

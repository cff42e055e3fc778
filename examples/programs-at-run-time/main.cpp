// A program module compiled when the program runs: the module's header is read from disk
// (normals.h beside this file, or --module FILE), Context::add_module compiles it with the
// system's C++ compiler for the CPU backend (cached on disk) and with NVRTC for the GPU,
// and its programs are then used by name, as a compiled-in module's are. Edit normals.h
// and run again: no rebuild.
//
//   programs-at-run-time [--module FILE.h] [--backend cpu|cuda|auto] [--jit-check SM]
//                        [--out FILE.png]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "lucent/lucent.h"
#include "scene/image_io.h"

namespace {

struct Args {
    lucent::ContextOptions options;
    std::string module = DEFAULT_MODULE;
    std::string out = "programs-at-run-time.png";
};

// The flags every example takes, and --module; false (after saying why) on a bad one.
bool parse_args(int argc, char** argv, Args& args) {
    using lucent::BackendKind;
    for (int i = 1; i < argc; i += 2) {
        const std::string flag = argv[i], value = i + 1 < argc ? argv[i + 1] : "";
        if (flag == "--backend" && (value == "cpu" || value == "cuda" || value == "auto")) {
            args.options.backend = value == "cpu"    ? BackendKind::kCpu
                                   : value == "cuda" ? BackendKind::kCuda
                                                     : BackendKind::kAuto;
        } else if (flag == "--jit-check" && std::atoi(value.c_str()) > 0) {
            args.options.jit_check_sm = std::atoi(value.c_str());
        } else if (flag == "--module" && !value.empty()) {
            args.module = value;
        } else if (flag == "--out" && !value.empty()) {
            args.out = value;
        } else {
            std::fprintf(stderr,
                         "programs-at-run-time: bad argument '%s %s'\nusage: "
                         "programs-at-run-time [--module FILE.h] [--backend cpu|cuda|auto] "
                         "[--jit-check SM] [--out FILE.png]\n",
                         flag.c_str(), value.c_str());
            return false;
        }
    }
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    Args args;
    if (!parse_args(argc, argv, args)) return 2;
    try {
        lucent::Context ctx(args.options);
        // Read, compiled (or taken from the cache) and loaded; the module names itself.
        const lucent::ModuleInfo& module =
            ctx.add_module(lucent::ModuleSource::from_file(args.module));
        auto camera = ctx.create_program(module, "camera");
        ctx.set_ray_type(0, lucent::RayTypeDesc{"radiance", ctx.create_program(module, "shade")
                                                                ->desc().payload});
        ctx.set_ray_generation_program(0, camera);
        ctx.set_miss_program(0, ctx.create_program(module, "background"));

        // Three triangles at different angles.
        auto vertices = ctx.create_buffer<float3>(lucent::BufferType::kInput, 9);
        vertices->upload(std::vector<float3>{{-1.6f, -0.8f, -3}, {-0.4f, -0.8f, -2.5f},
                                             {-1.0f, 0.8f, -3.5f}, {-0.5f, -0.7f, -3},
                                             {0.5f, -0.7f, -3}, {0, 0.9f, -3},
                                             {0.4f, -0.8f, -2.5f}, {1.6f, -0.8f, -3.5f},
                                             {1.0f, 0.8f, -2.8f}});
        auto triangles = ctx.create_geometry_triangles();
        triangles->set_vertices(vertices);
        auto material = ctx.create_material();
        material->set_closest_hit(0, ctx.create_program(module, "shade"));
        auto instance = ctx.create_geometry_instance();
        instance->set_geometry(triangles);
        instance->add_material(material);
        auto scene = ctx.create_geometry_group();
        scene->add_child(instance);

        const unsigned width = 640, height = 480;
        auto image = ctx.create_buffer<float3>(lucent::BufferType::kOutput, width, height);
        ctx["eye"] = make_float3(0, 0, 0);
        ctx["scene"] = scene;
        ctx["image"] = image;
        ctx.launch(0, width, height);

        const float3* pixels = image->data<float3>();
        const lucent::scene::Image png{width, height, {pixels, pixels + width * height}};
        lucent::scene::write_image(args.out, png);
        const auto lit = std::count_if(png.pixels.begin(), png.pixels.end(),
                                       [](float3 c) { return c.x + c.y + c.z > 0.5f; });
        std::printf("backend: %s\n", ctx.backend_name().c_str());
        std::printf("module '%s' from %s, compiled at run time\n",
                    std::string(module.name()).c_str(), args.module.c_str());
        if (args.options.jit_check_sm)
            std::printf("jit-check: megakernel compiled for sm_%d in %.0f ms%s\n",
                        args.options.jit_check_sm, ctx.last_launch().jit_ms,
                        ctx.last_launch().jit_cached ? " (from the cache)" : "");
        std::printf("the triangles cover %ld of %u pixels\n", long(lit), width * height);
        std::printf("wrote %s (%ux%u)\n", args.out.c_str(), width, height);
        if (lit < 1000) {
            std::fprintf(stderr, "programs-at-run-time: the triangles should be in view\n");
            return 1;
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "programs-at-run-time: %s\n", e.what());
        return 1;
    }
    return 0;
}

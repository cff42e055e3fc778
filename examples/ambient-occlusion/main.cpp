// An ambient-occlusion renderer written against Lucent's public API: it loads a mesh (an
// OBJ file, or a built-in scene), frames its bounding sphere with a pinhole camera, and
// writes the ambient occlusion seen from there as a PNG.
//
//   ambient-occlusion [MESH.obj] [--backend cpu|cuda|auto] [--jit-check SM]
//                     [--samples N] [--out FILE.png]
//
// The image depends only on the mesh and the sample count: the same on every run and, up to
// floating-point rounding, on every backend.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

#include "ambient_occlusion.h"
#include "lucent/lucent.h"
#include "scene/image_io.h"
#include "scene/obj_mesh.h"

namespace {

constexpr unsigned kWidth = 640, kHeight = 480;
constexpr float kPi = std::numbers::pi_v<float>;

struct Arguments {
    lucent::ContextOptions options;
    std::string mesh;  // empty: the built-in scene
    std::string out = "ambient-occlusion.png";
    unsigned samples = 16;
};

/// Parses the command line; false (after saying why) on a bad argument.
bool parse_args(int argc, char** argv, Arguments& a) {
    using lucent::BackendKind;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        const bool positional = flag.rfind("--", 0) != 0;
        const std::string value = positional || i + 1 >= argc ? "" : argv[++i];
        if (positional && a.mesh.empty()) {
            a.mesh = flag;
        } else if (flag == "--backend" && (value == "cpu" || value == "cuda" || value == "auto")) {
            a.options.backend = value == "cpu"    ? BackendKind::kCpu
                                : value == "cuda" ? BackendKind::kCuda
                                                  : BackendKind::kAuto;
        } else if (flag == "--jit-check" && std::atoi(value.c_str()) > 0) {
            a.options.jit_check_sm = std::atoi(value.c_str());  // e.g. 90: sm_90
        } else if (flag == "--samples" && std::atoi(value.c_str()) > 0) {
            a.samples = unsigned(std::atoi(value.c_str()));
        } else if (flag == "--out" && !value.empty()) {
            a.out = value;
        } else {
            std::fprintf(
                stderr,
                "ambient-occlusion: bad argument '%s%s%s'\nusage: ambient-occlusion [MESH.obj] "
                "[--backend cpu|cuda|auto] [--jit-check SM] "
                "[--samples N] [--out FILE.png]\n",
                flag.c_str(), value.empty() ? "" : " ", value.c_str());
            return false;
        }
    }
    return true;
}

// ---- the built-in scene: a torus, a box and a sphere on a floor ----------------------------

/// Adds a surface as a grid of rows x columns quads (two triangles each), its vertices at
/// point(u, v) for u, v from 0 to 1.
template <class Point>
void add_grid(lucent::scene::ObjMesh& mesh, unsigned rows, unsigned columns, Point point) {
    const unsigned base = unsigned(mesh.positions.size());
    for (unsigned r = 0; r <= rows; ++r)
        for (unsigned c = 0; c <= columns; ++c)
            mesh.positions.push_back(point(float(r) / float(rows), float(c) / float(columns)));
    for (unsigned r = 0; r < rows; ++r) {
        for (unsigned c = 0; c < columns; ++c) {
            const unsigned a = base + r * (columns + 1) + c, b = a + columns + 1;
            mesh.indices.push_back(make_uint3(a, b, b + 1));
            mesh.indices.push_back(make_uint3(a, b + 1, a + 1));
        }
    }
}

lucent::scene::ObjMesh built_in_scene() {
    lucent::scene::ObjMesh mesh;
    // The floor: 5 x 5 at y = 0.
    add_grid(mesh, 1, 1,
             [](float u, float v) { return make_float3(5 * u - 2.5f, 0, 5 * v - 2.5f); });
    // A torus lying on the floor (radii 0.8 and 0.3).
    add_grid(mesh, 64, 32, [](float u, float v) {
        const float d = 0.8f + 0.3f * std::cos(2 * kPi * v);
        return make_float3(-0.9f + d * std::cos(2 * kPi * u), 0.3f + 0.3f * std::sin(2 * kPi * v),
                           -0.3f + d * std::sin(2 * kPi * u));
    });
    // A sphere resting on the floor (radius 0.6).
    add_grid(mesh, 32, 64, [](float u, float v) {
        const float theta = kPi * u, phi = 2 * kPi * v;
        return make_float3(1.1f + 0.6f * std::sin(theta) * std::cos(phi),
                           0.6f + 0.6f * std::cos(theta),
                           0.9f + 0.6f * std::sin(theta) * std::sin(phi));
    });
    // A unit box, turned 30 degrees about the vertical: its six faces.
    const float c = std::cos(kPi / 6), s = std::sin(kPi / 6);
    auto box = [&](float x, float y, float z) {  // x, y, z in [-0.5, 0.5]
        return make_float3(1.0f + c * x - s * z, y + 0.5f, -1.1f + s * x + c * z);
    };
    for (int axis = 0; axis < 3; ++axis) {
        for (float side : {-0.5f, 0.5f}) {
            add_grid(mesh, 1, 1, [&](float u, float v) {
                float p[3];
                p[axis] = side, p[(axis + 1) % 3] = u - 0.5f, p[(axis + 2) % 3] = v - 0.5f;
                return box(p[0], p[1], p[2]);
            });
        }
    }
    return mesh;
}

// ---- the camera ------------------------------------------------------------------------------

struct PinholeCamera {
    float3 eye, U, V, W;
};

/// Looks at the centre of the mesh's bounding box from the front, above and to the right,
/// from just far enough back that all eight corners of the box are in view.
PinholeCamera frame_bounds(float3 lo, float3 hi, float aspect, float vfov_degrees = 40) {
    const float3 centre = 0.5f * (lo + hi);
    const float3 w = normalize(make_float3(-0.6f, -0.5f, -1.0f));  // the viewing direction
    const float3 u = normalize(cross(w, make_float3(0, 1, 0))), v = cross(u, w);
    const float tan_y = std::tan(0.5f * vfov_degrees * kPi / 180), tan_x = tan_y * aspect;
    // A corner q (from the centre) is in view when |dot(q, u)| <= tan_x * depth and
    // |dot(q, v)| <= tan_y * depth, with depth = distance + dot(q, w).
    float distance = 0;
    for (int i = 0; i < 8; ++i) {
        const float3 q =
            make_float3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z) - centre;
        distance = std::max({distance, std::fabs(dot(q, u)) / tan_x - dot(q, w),
                             std::fabs(dot(q, v)) / tan_y - dot(q, w)});
    }
    distance *= 1.05f;  // a margin
    return {centre - distance * w, u * (distance * tan_x), v * (distance * tan_y), distance * w};
}

}  // namespace

int main(int argc, char** argv) {
    Arguments args;
    if (!parse_args(argc, argv, args)) return 2;
    try {
        const lucent::scene::ObjMesh mesh =
            args.mesh.empty() ? built_in_scene() : lucent::scene::load_obj_mesh(args.mesh);
        float3 lo = mesh.positions[0], hi = lo;
        for (float3 p : mesh.positions) lo = fminf(lo, p), hi = fmaxf(hi, p);
        const float size = length(hi - lo);  // the bounding box's diagonal

        lucent::Context ctx(args.options);
        ctx.set_ray_type<ambient_occlusion::Payload>(ambient_occlusion::kRay, "radiance");
        ctx.set_max_recursion_depth(2);  // camera rays, then occlusion rays from their hits

        // The mesh: vertex and index buffers, one material that computes occlusion.
        auto positions =
            ctx.create_buffer<float3>(lucent::BufferType::kInput, unsigned(mesh.positions.size()));
        positions->upload(mesh.positions);
        auto indices =
            ctx.create_buffer<uint3>(lucent::BufferType::kInput, unsigned(mesh.indices.size()));
        indices->upload(mesh.indices);
        auto triangles = ctx.create_geometry_triangles();
        triangles->set_vertices(positions);
        triangles->set_indices(indices);
        auto material = ctx.create_material();
        material->set_closest_hit(ambient_occlusion::kRay,
                                  ctx.create_program(LUCENT_PROGRAM(ambient_occlusion::occlusion)));
        (*material)["radius"] = 0.1f * size;
        (*material)["epsilon"] = 1e-4f * size;
        auto instance = ctx.create_geometry_instance();
        instance->set_geometry(triangles);
        instance->add_material(material);
        auto group = ctx.create_geometry_group();
        group->add_child(instance);
        ctx["scene"] = group;

        const PinholeCamera view = frame_bounds(lo, hi, float(kWidth) / float(kHeight));
        auto image = ctx.create_buffer<float3>(lucent::BufferType::kOutput, kWidth, kHeight);
        auto camera = ctx.create_program(LUCENT_PROGRAM(ambient_occlusion::camera));
        (*camera)["eye"] = view.eye;
        (*camera)["U"] = view.U;
        (*camera)["V"] = view.V;
        (*camera)["W"] = view.W;
        (*camera)["samples"] = args.samples;
        (*camera)["image"] = image;
        ctx.set_ray_generation_program(0, camera);
        ctx.set_miss_program(ambient_occlusion::kRay,
                             ctx.create_program(LUCENT_PROGRAM(ambient_occlusion::background)));

        const auto start = std::chrono::steady_clock::now();
        ctx.launch(0, kWidth, kHeight);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();

        const float3* pixels = image->data<float3>();
        const lucent::scene::Image png{kWidth, kHeight, {pixels, pixels + kWidth * kHeight}};
        lucent::scene::write_image(args.out, png);
        double mean = 0;
        for (float3 p : png.pixels) mean += (p.x + p.y + p.z) / 3;
        mean /= double(png.pixels.size());

        const lucent::LaunchReport& report = ctx.last_launch();
        std::printf("backend: %s\n", ctx.backend_name().c_str());
        if (args.options.jit_check_sm)
            std::printf("jit-check: megakernel compiled for sm_%d in %.0f ms%s\n",
                        args.options.jit_check_sm, report.jit_ms,
                        report.jit_cached ? " (from the cache)" : "");
        else if (report.jit_ms > 0)  // the GPU compiled this module into its megakernel
            std::printf("megakernel: %.1f ms, %s\n", report.jit_ms,
                        report.jit_cached ? "loaded from the kernel cache" : "cold NVRTC compile");
        std::printf("mesh: %s, %zu triangles\n",
                    args.mesh.empty() ? "built-in scene" : args.mesh.c_str(), mesh.indices.size());
        std::printf("image: %ux%u, %u samples per pixel, mean value %.4f\n", kWidth, kHeight,
                    args.samples, mean);
        std::printf("time: %.0f ms, of which %.0f ms building the BVH\n", ms, report.accel_ms);
        std::printf("wrote %s\n", args.out.c_str());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "ambient-occlusion: %s\n", e.what());
        return 1;
    }
    return 0;
}

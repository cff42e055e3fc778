// Ray queries without an image: line of sight between many pairs of points, and the
// distance to the first surface along many rays (collision and proximity), against a
// triangle mesh. The queries go in as input buffers, one launch answers a whole batch, and
// the answers come back in output buffers. Then the same queries through
// scene::TriangleMesh, which takes arrays of rays and needs no programs.
//
//   ray-queries [MESH.obj] [--backend cpu|cuda|auto] [--jit-check SM] [--out FILE.txt]
//
// Without MESH.obj the mesh is a built-in torus. The queries are the same on every run and
// every backend (a hash of the query's index), so runs can be compared.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "lucent/lucent.h"
#include "ray_queries.h"
#include "scene/obj_mesh.h"
#include "scene/triangle_mesh.h"

namespace {

constexpr unsigned kPairs = 100000;  // line-of-sight queries
constexpr unsigned kRays = 100000;   // distance queries

struct Arguments {
    lucent::ContextOptions options;
    std::string mesh;  // empty: the built-in torus
    std::string out;   // empty: write no file
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
        } else if (flag == "--out" && !value.empty()) {
            a.out = value;
        } else {
            std::fprintf(stderr,
                         "ray-queries: bad argument '%s%s%s'\nusage: ray-queries [MESH.obj] "
                         "[--backend cpu|cuda|auto] [--jit-check SM] "
                         "[--out FILE.txt]\n",
                         flag.c_str(), value.empty() ? "" : " ", value.c_str());
            return false;
        }
    }
    return true;
}

/// A torus around the y axis (radii 1 and 0.4): a mesh with a hole, so some lines of sight
/// pass through it and some are blocked.
lucent::scene::ObjMesh make_torus(unsigned rings = 64, unsigned sides = 32) {
    const float R = 1.0f, r = 0.4f, two_pi = 2 * std::numbers::pi_v<float>;
    lucent::scene::ObjMesh mesh;
    for (unsigned i = 0; i < rings; ++i) {
        for (unsigned j = 0; j < sides; ++j) {
            const float u = two_pi * float(i) / float(rings), v = two_pi * float(j) / float(sides);
            const float d = R + r * std::cos(v);
            mesh.positions.push_back(
                make_float3(d * std::cos(u), r * std::sin(v), d * std::sin(u)));
            const unsigned a = i * sides + j, b = ((i + 1) % rings) * sides + j;
            const unsigned c = ((i + 1) % rings) * sides + (j + 1) % sides,
                           e = i * sides + (j + 1) % sides;
            mesh.indices.push_back(make_uint3(a, e, c));
            mesh.indices.push_back(make_uint3(a, c, b));
        }
    }
    return mesh;
}

/// A number in [0, 1) from a query's index and a stream (splitmix64's finaliser): the same
/// on every run and platform, unlike std::uniform_real_distribution.
float hash_unit(uint64_t index, uint64_t stream) {
    uint64_t z = index * 0x9E3779B97F4A7C15ull + stream * 0xD1B54A32D192ED03ull + 1;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return float((z ^ (z >> 31)) >> 40) * (1.0f / 16777216.0f);
}

/// The box queries are drawn from: the mesh's bounds, grown by a quarter on each side.
struct Box {
    float3 lo, extent;
    float3 point(uint64_t index, uint64_t stream) const {
        return lo + extent * make_float3(hash_unit(index, stream), hash_unit(index, stream + 1),
                                         hash_unit(index, stream + 2));
    }
};
Box query_box(const lucent::scene::ObjMesh& mesh) {
    float3 lo = mesh.positions[0], hi = lo;
    for (float3 p : mesh.positions) lo = fminf(lo, p), hi = fmaxf(hi, p);
    const float3 margin = 0.25f * (hi - lo);
    return {lo - margin, hi - lo + 2.0f * margin};
}

/// A direction uniform on the unit sphere.
float3 unit_direction(uint64_t index, uint64_t stream) {
    const float z = 1 - 2 * hash_unit(index, stream);
    const float phi = 2 * std::numbers::pi_v<float> * hash_unit(index, stream + 1);
    const float s = std::sqrt(std::fmax(0.0f, 1 - z * z));
    return make_float3(s * std::cos(phi), s * std::sin(phi), z);
}

template <class T>
std::shared_ptr<lucent::Buffer> input_buffer(lucent::Context& ctx, const std::vector<T>& values) {
    auto buffer = ctx.create_buffer<T>(lucent::BufferType::kInput, unsigned(values.size()));
    buffer->upload(values);
    return buffer;
}

double ms_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

}  // namespace

int main(int argc, char** argv) {
    Arguments args;
    if (!parse_args(argc, argv, args)) return 2;
    try {
        const lucent::scene::ObjMesh mesh =
            args.mesh.empty() ? make_torus() : lucent::scene::load_obj_mesh(args.mesh);
        const Box box = query_box(mesh);

        // The batches of queries.
        std::vector<float3> from(kPairs), to(kPairs), origin(kRays), direction(kRays);
        for (unsigned i = 0; i < kPairs; ++i) from[i] = box.point(i, 0), to[i] = box.point(i, 3);
        for (unsigned i = 0; i < kRays; ++i)
            origin[i] = box.point(i, 6), direction[i] = unit_direction(i, 9);

        lucent::Context ctx(args.options);
        // The programs by name, from the module this binary embeds (lucent_add_programs).
        ctx.add_module("ray_queries");
        ctx.set_ray_type<ray_queries::HitPayload>(ray_queries::kQueryRay, "query");
        ctx.set_miss_program(ray_queries::kQueryRay, ctx.create_program("record_miss"));

        // The mesh: one GeometryTriangles in one instance, under a GeometryGroup (its BVH).
        auto triangles = ctx.create_geometry_triangles();
        triangles->set_vertices(input_buffer(ctx, mesh.positions));
        triangles->set_indices(input_buffer(ctx, mesh.indices));
        auto material = ctx.create_material();
        material->set_closest_hit(ray_queries::kQueryRay, ctx.create_program("record_hit"));
        auto instance = ctx.create_geometry_instance();
        instance->set_geometry(triangles);
        instance->add_material(material);
        auto group = ctx.create_geometry_group();
        group->add_child(instance);
        ctx["mesh"] = group;

        // Entry 0: line of sight; entry 1: closest distance. Each reads its own buffers.
        ctx.set_entry_point_count(2);
        auto line_of_sight = ctx.create_program("line_of_sight");
        auto visible = ctx.create_buffer<unsigned>(lucent::BufferType::kOutput, kPairs);
        (*line_of_sight)["from"] = input_buffer(ctx, from);
        (*line_of_sight)["to"] = input_buffer(ctx, to);
        (*line_of_sight)["visible"] = visible;
        ctx.set_ray_generation_program(0, line_of_sight);
        auto closest = ctx.create_program("closest_distance");
        auto distance = ctx.create_buffer<float>(lucent::BufferType::kOutput, kRays);
        auto triangle = ctx.create_buffer<unsigned>(lucent::BufferType::kOutput, kRays);
        (*closest)["origin"] = input_buffer(ctx, origin);
        (*closest)["direction"] = input_buffer(ctx, direction);
        (*closest)["distance"] = distance;
        (*closest)["triangle"] = triangle;
        (*closest)["max_distance"] = lucent::kInfinity;
        ctx.set_ray_generation_program(1, closest);

        auto start = std::chrono::steady_clock::now();
        ctx.launch(0, kPairs);
        const lucent::LaunchReport first = ctx.last_launch();  // the one that compiled
        const double sight_ms = ms_since(start);
        start = std::chrono::steady_clock::now();
        ctx.launch(1, kRays);
        const double distance_ms = ms_since(start);

        // The answers, summed in index order (so the sums are the same for the same answers).
        const unsigned* v = visible->data<unsigned>();
        const float* t = distance->data<float>();
        const unsigned* tri = triangle->data<unsigned>();
        unsigned visible_count = 0, hits = 0;
        double distance_sum = 0, nearest = lucent::kInfinity;
        uint64_t triangle_sum = 0;
        for (unsigned i = 0; i < kPairs; ++i) visible_count += v[i];
        for (unsigned i = 0; i < kRays; ++i) {
            if (t[i] < 0) continue;
            ++hits;
            distance_sum += t[i];
            nearest = std::fmin(nearest, t[i]);
            triangle_sum += tri[i];
        }

        std::printf("backend: %s\n", ctx.backend_name().c_str());
        if (args.options.jit_check_sm)
            std::printf("jit-check: megakernel compiled for sm_%d in %.0f ms%s\n",
                        args.options.jit_check_sm, first.jit_ms,
                        first.jit_cached ? " (from the cache)" : "");
        std::printf("mesh: %s, %zu triangles\n",
                    args.mesh.empty() ? "built-in torus" : args.mesh.c_str(), mesh.indices.size());
        std::printf("line of sight: %u of %u pairs visible\n", visible_count, kPairs);
        std::printf("distance: %u of %u rays hit; nearest %.6f, mean %.6f\n", hits, kRays,
                    hits ? nearest : 0.0, hits ? distance_sum / hits : 0.0);
        std::printf("checksums: distance sum %.4f, triangle index sum %llu\n", distance_sum,
                    (unsigned long long)triangle_sum);
        std::printf(
            "time: line of sight %.1f ms, distance %.1f ms (with the first launch's setup)\n",
            sight_ms, distance_ms);

        // The same queries without writing programs: scene::TriangleMesh takes the rays as
        // arrays (on the CPU it traces them as ray streams, straight through the BVH; on the
        // GPU it launches its own query module). Its answers are the programs' answers.
        lucent::scene::TriangleMesh queries(mesh.positions, mesh.indices, args.options);
        std::vector<float3> segment(kPairs);
        for (unsigned i = 0; i < kPairs; ++i) segment[i] = to[i] - from[i];
        const std::vector<float> up_to_one{1.0f};  // tmax 1: the segment from `from` to `to`
        std::vector<uint8_t> blocked(kPairs);
        start = std::chrono::steady_clock::now();
        queries.occluded({from, segment, {}, up_to_one}, blocked);
        const double mesh_sight_ms = ms_since(start);
        std::vector<float> mesh_t(kRays);
        std::vector<int32_t> mesh_prim(kRays);
        std::vector<float2> mesh_uv(kRays);  // barycentrics and normals come with each hit
        std::vector<float3> mesh_normal(kRays);
        start = std::chrono::steady_clock::now();
        queries.intersect({origin, direction, {}, {}}, {mesh_t, mesh_prim, mesh_uv, mesh_normal});
        const double mesh_distance_ms = ms_since(start);
        unsigned same = 0;
        for (unsigned i = 0; i < kPairs; ++i) same += (blocked[i] == 0) == (v[i] == 1);
        for (unsigned i = 0; i < kRays; ++i) {
            const bool hit = t[i] >= 0;
            same += hit ? mesh_t[i] == t[i] : mesh_prim[i] < 0;
        }
        std::printf("TriangleMesh (%s): %u of %u answers the same; line of sight %.1f ms, "
                    "distance %.1f ms (with its BVH build)\n",
                    queries.backend_name().c_str(), same, kPairs + kRays, mesh_sight_ms,
                    mesh_distance_ms);

        if (!args.out.empty()) {
            std::ofstream file(args.out);
            file << "# ray-queries: " << kPairs << " line-of-sight pairs, then " << kRays
                 << " distance rays\n# pair visible\n";
            for (unsigned i = 0; i < kPairs; ++i) file << i << ' ' << v[i] << '\n';
            file << "# ray distance triangle (-1 -1: no hit)\n";
            char line[64];
            for (unsigned i = 0; i < kRays; ++i) {
                std::snprintf(line, sizeof line, "%u %.6g %d\n", i, t[i],
                              t[i] < 0 ? -1 : int(tri[i]));
                file << line;
            }
            if (!file.flush()) throw lucent::Error(args.out + ": cannot be written");
            std::printf("wrote %s\n", args.out.c_str());
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "ray-queries: %s\n", e.what());
        return 1;
    }
    return 0;
}

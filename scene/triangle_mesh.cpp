#include "scene/triangle_mesh.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <utility>

#include "lucent/error.h"
#include "scene/mesh_queries/cpu_mesh_queries.h"
#include "scene/obj_mesh.h"
#include "scene/scene.h"
// The query module's programs, compiled here for the CPU, and its text, embedded for the
// GPU's JIT and registered with the module list (generated from mesh_query_programs.h by
// lucent-embed-module). Included rather than compiled apart: in a static library an object
// that nothing references would be dropped at link time, and the module with it.
#include "mesh_query_programs.embed.cpp"

namespace lucent::scene {

namespace {

namespace programs = lucent_mesh_queries;
constexpr unsigned kClosestEntry = 0, kAnyEntry = 1;

std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

template <class T>
std::shared_ptr<Buffer> filled_buffer(Context& ctx, BufferType type, std::span<const T> values) {
    auto buffer = ctx.create_buffer<T>(type, unsigned(values.size()));
    std::copy(values.begin(), values.end(), buffer->template map<T>());
    buffer->unmap();
    return buffer;
}

/// lucent::Error "<where>: <what>" unless `size` is one of the sizes a span may have.
void check_size(const char* where, const char* what, size_t size, size_t rays, bool one_for_all) {
    if (size == rays || (one_for_all && size <= 1)) return;
    throw Error(std::string(where) + ": " + what + " has " + std::to_string(size) +
                " entries for " + std::to_string(rays) + " rays; give " +
                (one_for_all ? "one per ray, one for every ray, or none" : "one per ray"));
}

/// The rays after their sizes are checked (directions as origins, tmin and tmax one per ray,
/// one or none, at most 2^32 - 1 rays: a launch's width), with an empty tmin or tmax given
/// its default, so that both paths see one value for every ray or one per ray.
MeshRays checked_rays(const char* where, const MeshRays& rays) {
    static constexpr float kNoTmin = 0.0f, kNoTmax = kInfinity;
    const size_t n = rays.origins.size();
    check_size(where, "directions", rays.directions.size(), n, false);
    check_size(where, "tmin", rays.tmin.size(), n, true);
    check_size(where, "tmax", rays.tmax.size(), n, true);
    if (uint64_t(n) > 0xffffffffull)
        throw Error(std::string(where) + ": " + std::to_string(n) +
                    " rays in one call; at most 4294967295 (split the batch)");
    MeshRays r = rays;
    if (r.tmin.empty()) r.tmin = std::span<const float>(&kNoTmin, 1);
    if (r.tmax.empty()) r.tmax = std::span<const float>(&kNoTmax, 1);
    return r;
}

}  // namespace

MeshTriangles load_mesh_triangles(const std::string& path) {
    MeshTriangles mesh;
    if (lower_extension(path) == ".obj") {
        ObjMesh obj = load_obj_mesh(path);
        mesh.positions = std::move(obj.positions);
        mesh.indices = std::move(obj.indices);
        return mesh;
    }
    const Scene scene = load_scene(path);
    // Joined where the scene draws them: each instance's vertices in world space.
    for (const Instance& instance : drawn_instances(scene)) {
        const Mesh& m = scene.meshes[instance.mesh];
        const unsigned base = unsigned(mesh.positions.size());
        for (const float3& p : m.positions)
            mesh.positions.push_back(transform_point(instance.transform, p));
        for (uint3 tri : m.indices)
            mesh.indices.push_back(make_uint3(tri.x + base, tri.y + base, tri.z + base));
    }
    if (mesh.indices.empty()) throw Error(path + ": the scene has no triangles");
    return mesh;
}

struct TriangleMesh::Impl {
    mutable std::mutex mutex;
    size_t vertex_count = 0, triangle_count = 0;
    std::string backend_name;
    std::unique_ptr<detail::CpuMeshQueries> cpu;  // the CPU's direct queries, or
    std::unique_ptr<Context> ctx;                 // the engine's
    std::shared_ptr<Buffer> vertices;
    std::shared_ptr<Acceleration> accel;
    std::shared_ptr<Program> closest, any;
    // Rays in, answers out: sized for the last batch.
    size_t count = 0;
    std::shared_ptr<Buffer> origins, directions, tmin, tmax;
    std::shared_ptr<Buffer> t, prim, uv, normal, blocked;

    void build_engine_queries(std::span<const float3> positions, std::span<const uint3> indices);
    void load_rays(const MeshRays& rays);
};

TriangleMesh::TriangleMesh(std::span<const float3> vertices, std::span<const uint3> triangles,
                           ContextOptions options)
    : m_impl(std::make_unique<Impl>()) {
    if (vertices.empty())
        throw Error("TriangleMesh: no vertices; a mesh needs at least three vertices");
    for (size_t i = 0; i < triangles.size(); ++i) {
        const uint3 t = triangles[i];
        if (t.x >= vertices.size() || t.y >= vertices.size() || t.z >= vertices.size())
            throw Error("TriangleMesh: triangle " + std::to_string(i) + " is (" +
                        std::to_string(t.x) + ", " + std::to_string(t.y) + ", " +
                        std::to_string(t.z) + "), but there are " +
                        std::to_string(vertices.size()) + " vertices; every index must be below " +
                        std::to_string(vertices.size()));
    }
    Impl& m = *m_impl;
    m.vertex_count = vertices.size();
    m.triangle_count = triangles.size();
    const bool engine_on_cpu = options.jit_check_sm != 0 || !options.devices.empty();
    const unsigned threads = options.threads;
    // The Context decides the backend ("auto": the GPU if there is one) and names it.
    m.ctx = std::make_unique<Context>(std::move(options));
    m.backend_name = m.ctx->backend_name();
    if (!engine_on_cpu && m.backend_name.rfind("cpu", 0) == 0) {
        m.ctx.reset();  // its workers would idle beside the direct queries' own
        m.cpu = std::make_unique<detail::CpuMeshQueries>(vertices, triangles, threads);
        return;
    }
    m.build_engine_queries(vertices, triangles);
}

TriangleMesh TriangleMesh::load(const std::string& path, ContextOptions options) {
    const MeshTriangles mesh = load_mesh_triangles(path);
    return TriangleMesh(mesh.positions, mesh.indices, std::move(options));
}

TriangleMesh::~TriangleMesh() = default;
TriangleMesh::TriangleMesh(TriangleMesh&&) noexcept = default;
TriangleMesh& TriangleMesh::operator=(TriangleMesh&&) noexcept = default;

void TriangleMesh::Impl::build_engine_queries(std::span<const float3> positions,
                                              std::span<const uint3> indices) {
    Context& c = *ctx;
    c.add_module("lucent_mesh_queries");
    c.set_ray_type<programs::QueryHit>(programs::kQueryRay, "query");
    c.set_miss_program(programs::kQueryRay, c.create_program("record_miss"));

    vertices = filled_buffer(c, BufferType::kInput, positions);
    auto triangles = c.create_geometry_triangles();
    triangles->set_vertices(vertices);
    triangles->set_indices(filled_buffer(c, BufferType::kInput, indices));
    auto material = c.create_material();
    material->set_closest_hit(programs::kQueryRay, c.create_program("record_hit"));
    auto instance = c.create_geometry_instance();
    instance->set_geometry(triangles);
    instance->add_material(material);
    auto group = c.create_geometry_group();
    group->add_child(instance);
    accel = group->acceleration();
    c["mesh"] = group;

    c.set_entry_point_count(2);
    closest = c.create_program("closest_hits");
    any = c.create_program("any_hits");
    c.set_ray_generation_program(kClosestEntry, closest);
    c.set_ray_generation_program(kAnyEntry, any);

    // The batch buffers start at one ray; the first query sizes them.
    count = 1;
    origins = c.create_buffer<float3>(BufferType::kInput, 1);
    directions = c.create_buffer<float3>(BufferType::kInput, 1);
    tmin = c.create_buffer<float>(BufferType::kInput, 1);
    tmax = c.create_buffer<float>(BufferType::kInput, 1);
    c["origins"] = origins;
    c["directions"] = directions;
    c["tmin"] = tmin;
    c["tmax"] = tmax;
    t = c.create_buffer<float>(BufferType::kOutput, 1);
    prim = c.create_buffer<int>(BufferType::kOutput, 1);
    uv = c.create_buffer<float2>(BufferType::kOutput, 1);
    normal = c.create_buffer<float3>(BufferType::kOutput, 1);
    blocked = c.create_buffer<unsigned char>(BufferType::kOutput, 1);
    (*closest)["t"] = t;
    (*closest)["prim"] = prim;
    (*closest)["uv"] = uv;
    (*closest)["normal"] = normal;
    (*any)["blocked"] = blocked;
}

void TriangleMesh::Impl::load_rays(const MeshRays& rays) {
    // Output buffers must have the launch's size: a batch of another size resizes them all
    // (a recompile, no BVH work).
    const size_t n = rays.origins.size();
    if (n != count) {
        count = n;
        for (Buffer* b : {origins.get(), directions.get(), t.get(), prim.get(), uv.get(),
                          normal.get(), blocked.get()})
            b->resize(unsigned(n));
    }
    std::copy(rays.origins.begin(), rays.origins.end(), origins->map<float3>());
    origins->unmap();
    std::copy(rays.directions.begin(), rays.directions.end(), directions->map<float3>());
    directions->unmap();
    for (auto [buffer, v] : {std::pair{&tmin, rays.tmin}, std::pair{&tmax, rays.tmax}}) {
        // One value for all rays (size 1), or one per ray: a batch of one ray is both.
        Buffer& b = **buffer;
        if (b.count() != v.size()) b.resize(unsigned(v.size()));
        std::copy(v.begin(), v.end(), b.map<float>());
        b.unmap();
    }
}

TriangleMesh::Impl& TriangleMesh::impl(const char* where) const {
    if (!m_impl)
        throw Error(std::string(where) +
                    ": this TriangleMesh was moved from; use the one it "
                    "was moved to");
    return *m_impl;
}

void TriangleMesh::intersect(const MeshRays& given, const MeshHits& out) {
    const char* where = "TriangleMesh::intersect";
    Impl& m = impl(where);
    const MeshRays rays = checked_rays(where, given);  // empty intervals given defaults
    const size_t n = rays.origins.size();
    check_size(where, "out.t", out.t.size(), n, false);
    check_size(where, "out.prim", out.prim.size(), n, false);
    check_size(where, "out.uv", out.uv.size(), n, false);
    check_size(where, "out.normal", out.normal.size(), n, false);
    if (n == 0) return;
    std::lock_guard lock(m.mutex);
    if (m.cpu) return m.cpu->intersect(rays, out);
    m.load_rays(rays);
    m.ctx->launch(kClosestEntry, unsigned(n));
    std::copy_n(m.t->data<float>(), n, out.t.begin());
    std::copy_n(m.prim->data<int>(), n, out.prim.begin());
    std::copy_n(m.uv->data<float2>(), n, out.uv.begin());
    std::copy_n(m.normal->data<float3>(), n, out.normal.begin());
}

void TriangleMesh::occluded(const MeshRays& given, std::span<uint8_t> blocked) {
    const char* where = "TriangleMesh::occluded";
    Impl& m = impl(where);
    const MeshRays rays = checked_rays(where, given);  // empty intervals given defaults
    const size_t n = rays.origins.size();
    check_size(where, "blocked", blocked.size(), n, false);
    if (n == 0) return;
    std::lock_guard lock(m.mutex);
    if (m.cpu) return m.cpu->occluded(rays, blocked);
    m.load_rays(rays);
    m.ctx->launch(kAnyEntry, unsigned(n));
    std::copy_n(m.blocked->data<unsigned char>(), n, blocked.begin());
}

void TriangleMesh::update(std::span<const float3> vertices, bool rebuild) {
    Impl& m = impl("TriangleMesh::update");
    std::lock_guard lock(m.mutex);
    if (vertices.size() != m.vertex_count)
        throw Error("TriangleMesh::update: " + std::to_string(vertices.size()) +
                    " vertices for a mesh of " + std::to_string(m.vertex_count) +
                    "; make a new TriangleMesh for another vertex count");
    if (m.cpu) return m.cpu->update(vertices, rebuild);
    m.accel->set_refit(!rebuild);
    std::copy(vertices.begin(), vertices.end(), m.vertices->map<float3>());
    m.vertices->unmap();  // the acceleration structure is refitted or rebuilt at the next launch
}

size_t TriangleMesh::vertex_count() const {
    return impl("TriangleMesh::vertex_count").vertex_count;
}
size_t TriangleMesh::triangle_count() const {
    return impl("TriangleMesh::triangle_count").triangle_count;
}
std::string TriangleMesh::backend_name() const {
    return impl("TriangleMesh::backend_name").backend_name;
}
LaunchReport TriangleMesh::last_launch() const {
    const Impl& m = impl("TriangleMesh::last_launch");
    std::lock_guard lock(m.mutex);
    return m.cpu ? m.cpu->last_launch() : m.ctx->last_launch();
}

}  // namespace lucent::scene

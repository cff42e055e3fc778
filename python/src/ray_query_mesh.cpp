#include "ray_query_mesh.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <tuple>

#include "ray_query_programs.h"
#include "scene/obj_mesh.h"
#include "scene/scene.h"

namespace lucent::python {

namespace {

constexpr unsigned kClosestEntry = 0, kAnyEntry = 1;

std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

template <class T>
std::shared_ptr<Buffer> filled_buffer(Context& ctx, BufferType type, const T* values,
                                      size_t count) {
    auto buffer = ctx.create_buffer<T>(type, unsigned(count));
    std::memcpy(buffer->template map<T>(), values, count * sizeof(T));
    buffer->unmap();
    return buffer;
}

}  // namespace

MeshData load_mesh(const std::string& path) {
    MeshData mesh;
    if (lower_extension(path) == ".obj") {
        scene::ObjMesh obj = scene::load_obj_mesh(path);
        mesh.positions = std::move(obj.positions);
        mesh.indices = std::move(obj.indices);
        return mesh;
    }
    const scene::Scene scene = scene::load_scene(path);
    // Joined where the scene draws them: each instance's vertices in world space.
    for (const scene::Instance& instance : scene::drawn_instances(scene)) {
        const scene::Mesh& m = scene.meshes[instance.mesh];
        const unsigned base = unsigned(mesh.positions.size());
        for (const float3& p : m.positions)
            mesh.positions.push_back(transform_point(instance.transform, p));
        for (uint3 tri : m.indices)
            mesh.indices.push_back(make_uint3(tri.x + base, tri.y + base, tri.z + base));
    }
    if (mesh.indices.empty()) throw Error(path + ": the scene has no triangles");
    return mesh;
}

RayQueryMesh::RayQueryMesh(const float* vertices, size_t vertex_count, const uint32_t* indices,
                           size_t triangle_count, ContextOptions options)
    : m_vertex_count(vertex_count), m_triangle_count(triangle_count) {
    const bool engine_on_cpu = options.jit_check_sm != 0 || !options.devices.empty();
    const unsigned threads = options.threads;
    // The Context decides the backend ("auto": the GPU if there is one) and names it.
    m_ctx = std::make_unique<Context>(std::move(options));
    m_backend_name = m_ctx->backend_name();
    if (!engine_on_cpu && m_backend_name.rfind("cpu", 0) == 0) {
        m_ctx.reset();  // its workers would idle beside the direct queries' own
        m_cpu = std::make_unique<CpuRayQueries>(vertices, vertex_count, indices, triangle_count,
                                                threads);
        return;
    }
    build_engine_queries(vertices, indices);
}

void RayQueryMesh::build_engine_queries(const float* vertices, const uint32_t* indices) {
    Context& ctx = *m_ctx;
    const size_t vertex_count = m_vertex_count, triangle_count = m_triangle_count;
    ctx.add_module("lucent_python_queries");
    ctx.set_ray_type<lucent_python::QueryHit>(lucent_python::kQueryRay, "query");
    ctx.set_miss_program(lucent_python::kQueryRay, ctx.create_program("record_miss"));

    m_vertices = filled_buffer(ctx, BufferType::kInput,
                               reinterpret_cast<const float3*>(vertices), vertex_count);
    auto triangles = ctx.create_geometry_triangles();
    triangles->set_vertices(m_vertices);
    triangles->set_indices(filled_buffer(ctx, BufferType::kInput,
                                         reinterpret_cast<const uint3*>(indices), triangle_count));
    auto material = ctx.create_material();
    material->set_closest_hit(lucent_python::kQueryRay, ctx.create_program("record_hit"));
    auto instance = ctx.create_geometry_instance();
    instance->set_geometry(triangles);
    instance->add_material(material);
    auto group = ctx.create_geometry_group();
    group->add_child(instance);
    m_accel = group->acceleration();
    ctx["mesh"] = group;

    ctx.set_entry_point_count(2);
    m_closest = ctx.create_program("closest_hits");
    m_any = ctx.create_program("any_hits");
    ctx.set_ray_generation_program(kClosestEntry, m_closest);
    ctx.set_ray_generation_program(kAnyEntry, m_any);

    // The batch buffers start at one ray; the first query sizes them.
    m_count = 1;
    m_origins = ctx.create_buffer<float3>(BufferType::kInput, 1);
    m_directions = ctx.create_buffer<float3>(BufferType::kInput, 1);
    m_tmin = ctx.create_buffer<float>(BufferType::kInput, 1);
    m_tmax = ctx.create_buffer<float>(BufferType::kInput, 1);
    ctx["origins"] = m_origins;
    ctx["directions"] = m_directions;
    ctx["tmin"] = m_tmin;
    ctx["tmax"] = m_tmax;
    m_t = ctx.create_buffer<float>(BufferType::kOutput, 1);
    m_prim = ctx.create_buffer<int>(BufferType::kOutput, 1);
    m_uv = ctx.create_buffer<float2>(BufferType::kOutput, 1);
    m_normal = ctx.create_buffer<float3>(BufferType::kOutput, 1);
    m_blocked = ctx.create_buffer<unsigned char>(BufferType::kOutput, 1);
    (*m_closest)["t"] = m_t;
    (*m_closest)["prim"] = m_prim;
    (*m_closest)["uv"] = m_uv;
    (*m_closest)["normal"] = m_normal;
    (*m_any)["blocked"] = m_blocked;
}

std::string RayQueryMesh::backend_name() const {
    return m_backend_name;
}

LaunchReport RayQueryMesh::last_launch() const {
    std::lock_guard lock(m_mutex);
    return m_cpu ? m_cpu->last_launch() : m_ctx->last_launch();
}

void RayQueryMesh::update(const float* vertices, size_t vertex_count, bool rebuild) {
    std::lock_guard lock(m_mutex);
    if (vertex_count != m_vertex_count)
        throw Error("update: " + std::to_string(vertex_count) + " vertices for a mesh of " +
                    std::to_string(m_vertex_count) + "; make a new TriangleMesh");
    if (m_cpu) return m_cpu->update(vertices, rebuild);
    m_accel->set_refit(!rebuild);
    std::memcpy(m_vertices->map<float3>(), vertices, vertex_count * sizeof(float3));
    m_vertices->unmap();  // the acceleration structure is refitted or rebuilt at the next launch
}

void RayQueryMesh::load_rays(const RayArrays& rays) {
    // Output buffers must have the launch's size: a batch of another size resizes them all
    // (a recompile, no BVH work).
    if (rays.count != m_count) {
        m_count = rays.count;
        const unsigned n = unsigned(m_count);
        for (Buffer* b : {m_origins.get(), m_directions.get(), m_t.get(), m_prim.get(), m_uv.get(),
                          m_normal.get(), m_blocked.get()})
            b->resize(n);
    }
    std::memcpy(m_origins->map<float3>(), rays.origins, rays.count * sizeof(float3));
    m_origins->unmap();
    std::memcpy(m_directions->map<float3>(), rays.directions, rays.count * sizeof(float3));
    m_directions->unmap();
    for (auto [buffer, values, count] : {std::tuple{&m_tmin, rays.tmin, rays.tmin_count},
                                         std::tuple{&m_tmax, rays.tmax, rays.tmax_count}}) {
        // One value for all rays (size 1), or one per ray: a batch of one ray is both.
        Buffer& b = **buffer;
        if (b.count() != count) b.resize(unsigned(count));
        std::memcpy(b.map<float>(), values, count * sizeof(float));
        b.unmap();
    }
}

void RayQueryMesh::intersect(const RayArrays& rays, const HitArrays& out) {
    if (rays.count == 0) return;
    std::lock_guard lock(m_mutex);
    if (m_cpu) return m_cpu->intersect(rays, out);
    load_rays(rays);
    m_ctx->launch(kClosestEntry, unsigned(rays.count));
    std::memcpy(out.t, m_t->data<float>(), rays.count * sizeof(float));
    std::memcpy(out.prim, m_prim->data<int>(), rays.count * sizeof(int32_t));
    std::memcpy(out.uv, m_uv->data<float2>(), rays.count * sizeof(float2));
    std::memcpy(out.normal, m_normal->data<float3>(), rays.count * sizeof(float3));
}

void RayQueryMesh::occluded(const RayArrays& rays, uint8_t* out) {
    if (rays.count == 0) return;
    std::lock_guard lock(m_mutex);
    if (m_cpu) return m_cpu->occluded(rays, out);
    load_rays(rays);
    m_ctx->launch(kAnyEntry, unsigned(rays.count));
    std::memcpy(out, m_blocked->data<unsigned char>(), rays.count);
}

}  // namespace lucent::python

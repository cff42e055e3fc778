#include "cuda/backend/gpu_scene.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <set>

#include "core/triangle_gather.h"
#include "cuda/jit/megakernel_compiler.h"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {
template <class T>
void put(DeviceBuffer& memory, const std::vector<T>& values) {
    if (values.empty())
        memory.reset();
    else
        memory.upload(values.data(), values.size() * sizeof(T));
}

static_assert(unsigned(PrimitiveType::kCustom) == gpu::kGpuCustom &&
                  unsigned(PrimitiveType::kTriangles) == gpu::kGpuTriangles &&
                  unsigned(PrimitiveType::kSpheres) == gpu::kGpuSpheres &&
                  unsigned(PrimitiveType::kCurves) == gpu::kGpuCurves,
              "GpuInstance::type holds lucent::PrimitiveType's values");

const Acceleration& acceleration_of(const core::CompiledNode& node) {
    return *static_cast<const GeometryGroup*>(node.source)->acceleration();
}

/// Appends `bvh`'s nodes and leaf order. `refs`, kept as long as `order`, gets each leaf
/// slot's primitive resolved by `resolve` (GeometryGroups), or a placeholder (Groups).
void append_bvh(const accel::Bvh& bvh, std::vector<gpu::GpuBvhNode>& nodes,
                std::vector<unsigned>& order, std::vector<gpu::GpuPrimRef>& refs,
                gpu::GpuBvh& out,
                const std::function<gpu::GpuPrimRef(unsigned)>& resolve = {}) {
    if (bvh.empty()) {
        out = {~0u, 0};
        return;
    }
    out = {unsigned(nodes.size()), unsigned(order.size())};
    for (const accel::BvhNode& n : bvh.nodes()) nodes.push_back({n.lo, n.first, n.hi, n.count});
    order.insert(order.end(), bvh.prim_order().begin(), bvh.prim_order().end());
    for (unsigned ref : bvh.prim_order())
        refs.push_back(resolve ? resolve(ref) : gpu::GpuPrimRef{0, 0});
}
}  // namespace

CUdeviceptr GpuScene::device_pointer(const std::shared_ptr<const Buffer>& shared) {
    if (!shared) return 0;
    const Buffer* buffer = shared.get();
    auto found = m_buffers.find(buffer);
    if (found == m_buffers.end()) {
        // Used by the new compile: reuse the previous compile's copy when there is one.
        auto previous = m_previous_buffers.find(buffer);
        if (previous != m_previous_buffers.end()) {
            found = m_buffers.emplace(buffer, std::move(previous->second)).first;
            m_previous_buffers.erase(previous);  // what is left there was dropped
        } else {
            found = m_buffers.emplace(buffer, BufferMirror{}).first;
        }
    }
    BufferMirror& m = found->second;
    m.buffer = shared;
    size_t bytes = buffer->count() * buffer->element().size;
    if (m.version != buffer->version() || m.memory.size() != bytes) {
        const auto start = std::chrono::steady_clock::now();
        if (buffer->zeroed()) {
            // Zeros (a new output image, an accumulator): cleared on the device rather than
            // copied from pageable host memory.
            m.memory.alloc(bytes);
            m.memory.fill(0);
            m_mirror_uploads.cleared += 1;
        } else {
            m.memory.upload(buffer->raw(), bytes);
            m_mirror_uploads.count += 1;
            m_mirror_uploads.bytes += bytes;
        }
        m.version = buffer->version();
        m_mirror_uploads.ms +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
    }
    return m.memory.ptr();
}

void GpuScene::patch_record(unsigned char* bytes, const core::CompiledProgram& program) {
    // Host pointers in the packed record become device pointers of the same buffers.
    auto device_of = [&](const void* host) -> CUdeviceptr {
        for (const auto& b : program.buffers)
            if (b->raw() == host) return device_pointer(b);
        return 0;
    };
    for (const FieldInfo& field : program.desc->record->fields) {
        unsigned char* at = bytes + field.offset;
        switch (field.kind) {
            case FieldKind::kBuffer: {
                void* host;
                std::memcpy(&host, at, sizeof host);
                CUdeviceptr d = device_of(host);
                std::memcpy(at, &d, sizeof d);
                break;
            }
            case FieldKind::kTexture: {
                TextureView view;
                std::memcpy(&view, at, sizeof view);
                view.texels = reinterpret_cast<const float4*>(device_of(view.texels));
                std::memcpy(at, &view, sizeof view);
                break;
            }
            case FieldKind::kCallable: {
                struct Erased {
                    void* fn;
                    const void* record;
                } c;
                std::memcpy(&c, at, sizeof c);
                auto found = m_callable_slots.find(c.record);
                if (found == m_callable_slots.end())
                    throw Error(program.label + ": a callable's record is missing from the scene");
                // On the GPU: {dispatch id, record offset in the blob}.
                c.fn = reinterpret_cast<void*>(uintptr_t(found->second.id));
                c.record = reinterpret_cast<const void*>(uintptr_t(found->second.record));
                std::memcpy(at, &c, sizeof c);
                break;
            }
            default:
                break;
        }
    }
}

unsigned GpuScene::reserve_record(const core::CompiledProgram& program) {
    size_t offset = (m_records.size() + 15) / 16 * 16;
    m_records.resize(offset + std::max<size_t>(program.desc->record->size, 16));
    return unsigned(offset);
}

void GpuScene::write_record(unsigned offset, const core::CompiledProgram& program) {
    std::memcpy(m_records.data() + offset, program.rec(), program.desc->record->size);
    patch_record(m_records.data() + offset, program);
}

gpu::ProgramRef GpuScene::add_program(const core::CompiledProgram& program) {
    if (!program) return {-1, 0};
    unsigned offset = reserve_record(program);
    write_record(offset, program);
    return {m_programs.id(program), offset};
}

/// The scene's tables as the GPU reads them, built on the host before the upload.
struct GpuScene::FlatScene {
    std::vector<gpu::ProgramRef> miss;
    std::vector<gpu::GpuInstance> instances;
    std::vector<gpu::GpuMaterialSlot> materials;
    std::vector<gpu::GpuNode> nodes;
    std::vector<unsigned> children, accel_instances, accel_prim_first, order;
    std::vector<gpu::GpuPrimRef> prim_refs;
    std::vector<gpu::GpuBvhNode> bvh_nodes;
    std::vector<gpu::GpuBvh> bvhs;
    std::vector<gpu::GpuGeometryAccel> accels;
    std::set<const core::GeometryAccel*> used_geometry;  // this compile's triangle layouts
};

void GpuScene::update(const core::CompiledScene& scene) {
    m_accel_ms = 0;
    m_upgraded_in_update = 0;
    // Only buffers this compile uses stay mirrored: others may no longer exist.
    m_previous_buffers = std::move(m_buffers);
    m_buffers.clear();
    // The order matters: records are laid out as programs are added.
    FlatScene flat;
    // LUCENT_GPU_ACCEL_TIMES=1 prints where the update's time goes, step by step.
    const bool print_times = std::getenv("LUCENT_GPU_ACCEL_TIMES") != nullptr;
    auto last = std::chrono::steady_clock::now();
    auto lap = [&] {
        const auto now = std::chrono::steady_clock::now();
        const double ms = std::chrono::duration<double, std::milli>(now - last).count();
        last = now;
        return ms;
    };
    m_mirror_uploads = {};
    add_programs(scene, flat);
    const double programs_ms = lap();
    flatten_instances(scene, flat);
    const double instances_ms = lap();
    flatten_nodes(scene, flat);
    const double nodes_ms = lap();
    upload(scene, flat);
    set_params(scene);
    drop_unused(flat);
    const double upload_ms = lap();
    if (print_times)
        std::fprintf(stderr,
                     "lucent: GPU scene: programs %.3f ms, instances %.3f ms, nodes %.3f ms "
                     "(layouts %.3f ms), flat arrays %.3f ms; buffer mirrors: %u uploaded "
                     "(%.1f MB) and %u cleared in %.3f ms\n",
                     programs_ms, instances_ms, nodes_ms, m_accel_ms, upload_ms,
                     m_mirror_uploads.count, m_mirror_uploads.bytes / 1e6,
                     m_mirror_uploads.cleared, m_mirror_uploads.ms);
}

void GpuScene::add_programs(const core::CompiledScene& scene, FlatScene& flat) {
    m_programs = build_program_table(scene);
    m_records.clear();
    m_entries.clear();
    // Callables first: records that call them need their ids and record offsets, and they
    // may call each other, so every slot is reserved before any record is written.
    m_callable_slots.clear();
    for (const core::CompiledProgram& c : scene.callables)
        m_callable_slots[c.rec()] = {m_programs.id(c), reserve_record(c)};
    for (const core::CompiledProgram& c : scene.callables)
        write_record(m_callable_slots[c.rec()].record, c);
    for (const core::CompiledEntry& e : scene.entries)
        m_entries.emplace_back(add_program(e.ray_generation), add_program(e.exception));
    for (const core::CompiledProgram& m : scene.miss) flat.miss.push_back(add_program(m));
}

void GpuScene::flatten_instances(const core::CompiledScene& scene, FlatScene& flat) {
    // Instances and their material slots.
    const unsigned ray_types = unsigned(scene.ray_types.size());
    for (const core::CompiledInstance& inst : scene.instances) {
        gpu::GpuInstance g{};
        g.type = unsigned(inst.type);
        g.prim_count = inst.primitive_count;
        g.opaque = inst.opaque;
        g.visibility_mask = inst.visibility_mask;
        g.user_id = inst.user_id;
        g.intersection = add_program(inst.intersection);
        g.attribute = add_program(inst.attribute);
        if (const GeometryTriangles* tris = inst.triangle_geometry()) {
            g.vertices = reinterpret_cast<const float3*>(device_pointer(tris->vertices()));
            g.indices = reinterpret_cast<const uint3*>(device_pointer(tris->indices()));
            g.material_indices =
                reinterpret_cast<const unsigned*>(device_pointer(tris->material_indices()));
        }
        if (inst.type == PrimitiveType::kSpheres) {
            auto& spheres = static_cast<const GeometrySpheres&>(*inst.source->geometry());
            g.centers = reinterpret_cast<const float3*>(device_pointer(spheres.centers()));
            g.radii = reinterpret_cast<const float*>(device_pointer(spheres.radii()));
            g.single_radius = inst.single_radius;
            g.material_indices =
                reinterpret_cast<const unsigned*>(device_pointer(spheres.material_indices()));
        }
        if (inst.type == PrimitiveType::kCurves) {
            auto& curves = static_cast<const GeometryCurves&>(*inst.source->geometry());
            g.vertices = reinterpret_cast<const float3*>(device_pointer(curves.vertices()));
            g.radii = reinterpret_cast<const float*>(device_pointer(curves.radii()));
            g.segments =
                reinterpret_cast<const unsigned*>(device_pointer(curves.segment_indices()));
            g.curve_type = inst.curve_type;
            g.material_indices =
                reinterpret_cast<const unsigned*>(device_pointer(curves.material_indices()));
        }
        g.motion = inst.motion;
        g.motion_points = inst.motion_points;
        g.material_offset = unsigned(flat.materials.size() / std::max(1u, ray_types));
        g.material_count = unsigned(inst.materials.size());
        for (const core::CompiledMaterial& m : inst.materials)
            for (unsigned r = 0; r < ray_types; ++r)
                flat.materials.push_back(
                    {add_program(m.closest_hit[r]), add_program(m.any_hit[r])});
        flat.instances.push_back(g);
    }
}

void GpuScene::flatten_nodes(const core::CompiledScene& scene, FlatScene& flat) {
    // Nodes, their children and acceleration structures.
    for (const core::CompiledNode& n : scene.nodes) {
        gpu::GpuNode g{};
        g.kind = unsigned(n.kind);
        g.first = unsigned(flat.children.size());
        g.count = unsigned(n.children.size());
        flat.children.insert(flat.children.end(), n.children.begin(), n.children.end());
        g.visit = add_program(n.visit);
        g.to_world = n.to_world;
        g.to_object = n.to_object;
        g.motion = n.motion;
        g.visibility_mask = n.visibility_mask;
        g.instance_id = n.instance_id;
        g.accel = ~0u;
        if (n.kind == NodeKind::kGroup && !n.brute_force) {
            g.accel = unsigned(flat.bvhs.size());
            flat.bvhs.emplace_back();
            append_bvh(n.child_bvh, flat.bvh_nodes, flat.order, flat.prim_refs, flat.bvhs.back());
        } else if (n.kind == NodeKind::kGeometryGroup) {
            g.accel = unsigned(flat.accels.size());
            flat.accels.push_back(flatten_geometry_accel(scene, n, flat));
        }
        flat.nodes.push_back(g);
    }
}

gpu::GpuGeometryAccel GpuScene::flatten_geometry_accel(const core::CompiledScene& scene,
                                                       const core::CompiledNode& n,
                                                       FlatScene& flat) {
    const core::GeometryAccel& ga = *n.geometry;
    gpu::GpuGeometryAccel a{};
    a.triangles_only = ga.triangles_only;
    a.brute_force = n.brute_force;
    for (unsigned r = 0; r < n.any_hit_for_ray_type.size(); ++r) {
        if (n.any_hit_for_ray_type[r]) a.any_hit_mask |= 1u << r;
        if (n.any_hit_enforced_for_ray_type[r]) a.any_hit_enforced_mask |= 1u << r;
    }
    a.instances_masked = n.instances_masked;
    a.instance_offset = unsigned(flat.accel_instances.size());
    a.instance_count = unsigned(n.instances.size());
    flat.accel_instances.insert(flat.accel_instances.end(), n.instances.begin(),
                                n.instances.end());
    a.prim_first_offset = unsigned(flat.accel_prim_first.size());
    flat.accel_prim_first.insert(flat.accel_prim_first.end(), ga.prim_first.begin(),
                                 ga.prim_first.end());
    a.prim_total = 0;
    for (unsigned i : n.instances) a.prim_total += scene.instances[i].bvh_references();
    if (ga.triangles_only) {
        // The CPU keeps its wide layout; the GPU gets its own over the same triangles,
        // rebuilt only when they change.
        GeometryMirror& mirror = m_geometry[&ga];
        flat.used_geometry.insert(&ga);
        update_triangle_bvh(scene, n, mirrored_triangles(scene, n), mirror);
        a.triangles = mirror.bvh.view();
        a.bvh = {~0u, 0};
        if (mirror.empty) a.triangles_only = 0, a.prim_total = 0;  // nothing to hit
    } else {
        // A global primitive ref counts through the instances in order: instance k
        // holds refs prim_first[k] .. prim_first[k + 1] - 1.
        auto resolve = [&](unsigned ref) {
            const auto k =
                unsigned(std::upper_bound(ga.prim_first.begin(), ga.prim_first.end(), ref) -
                         ga.prim_first.begin() - 1);
            return gpu::GpuPrimRef{n.instances[k], ref - ga.prim_first[k]};
        };
        append_bvh(ga.bvh, flat.bvh_nodes, flat.order, flat.prim_refs, a.bvh, resolve);
    }
    return a;
}

void GpuScene::upload(const core::CompiledScene& scene, const FlatScene& flat) {
    put(m_nodes, flat.nodes);
    put(m_children, flat.children);
    put(m_bvh_nodes, flat.bvh_nodes);
    put(m_prim_order, flat.order);
    put(m_prim_refs, flat.prim_refs);
    put(m_bvhs, flat.bvhs);
    put(m_accels, flat.accels);
    put(m_accel_instances, flat.accel_instances);
    put(m_accel_prim_first, flat.accel_prim_first);
    put(m_instances, flat.instances);
    put(m_materials, flat.materials);
    put(m_record_blob, m_records);
    put(m_miss, flat.miss);
    std::vector<unsigned> signatures;
    for (const RayTypeDesc& r : scene.ray_types)
        signatures.push_back(unsigned(r.payload->size << 8 | r.payload->align));
    put(m_payload_signatures, signatures);
    put(m_motion, scene.motion);
}

void GpuScene::set_params(const core::CompiledScene& scene) {
    m_params = gpu::LaunchParams{};
    m_params.nodes = m_nodes.as<gpu::GpuNode>();
    m_params.children = m_children.as<unsigned>();
    m_params.bvh_nodes = m_bvh_nodes.as<gpu::GpuBvhNode>();
    m_params.prim_order = m_prim_order.as<unsigned>();
    m_params.prim_refs = m_prim_refs.as<gpu::GpuPrimRef>();
    m_params.bvhs = m_bvhs.as<gpu::GpuBvh>();
    m_params.accels = m_accels.as<gpu::GpuGeometryAccel>();
    m_params.accel_instances = m_accel_instances.as<unsigned>();
    m_params.accel_prim_first = m_accel_prim_first.as<unsigned>();
    m_params.instances = m_instances.as<gpu::GpuInstance>();
    m_params.materials = m_materials.as<gpu::GpuMaterialSlot>();
    m_params.records = m_record_blob.as<unsigned char>();
    m_params.miss = m_miss.as<gpu::ProgramRef>();
    m_params.ray_type_count = unsigned(scene.ray_types.size());
    m_params.payload_signatures = m_payload_signatures.as<unsigned>();
    m_params.motion = m_motion.as<float>();
    m_params.node_count = unsigned(scene.nodes.size());
    m_params.max_depth = scene.max_depth;
    m_params.print_enabled = scene.print_enabled;
    m_params.print_index = scene.print_index;
    for (int code : scene.enabled_exceptions) {
        if (code == kAllExceptions)
            m_params.exception_mask = ~0u;
        else if (code >= kUserExceptionBase)
            m_params.exception_mask |= 1u << 31;
        else if (code > 0 && code < 31)
            m_params.exception_mask |= 1u << code;
    }
}

void GpuScene::drop_unused(const FlatScene& flat) {
    for (auto it = m_geometry.begin(); it != m_geometry.end();)
        it = flat.used_geometry.count(it->first) ? std::next(it) : m_geometry.erase(it);
    // Buffers the new compile dropped: what the GPU wrote into them reaches the host now.
    for (auto& [buffer, mirror] : m_previous_buffers)
        if (mirror.device_newer) fetch_mirror(mirror);
    m_previous_buffers.clear();
}

void GpuScene::sync_buffers() {
    for (auto& [buffer, mirror] : m_buffers) device_pointer(mirror.buffer);
}

void GpuScene::mark_outputs_device_newer() {
    for (auto& [buffer, mirror] : m_buffers)
        if (buffer->type() != BufferType::kInput) {
            mirror.device_newer = true;
            buffer->mark_device_newer();
        }
}

void GpuScene::fetch_mirror(BufferMirror& mirror) {
    const Buffer& b = *mirror.buffer;
    mirror.memory.download(const_cast<void*>(b.raw()), b.count() * b.element().size);
    b.mark_written();
    mirror.device_newer = false;
}

CUdeviceptr GpuScene::mirror(const Buffer& buffer) const {
    auto found = m_buffers.find(&buffer);
    return found == m_buffers.end() ? 0 : found->second.memory.ptr();
}

CUdeviceptr GpuScene::current_mirror(const Buffer& buffer) const {
    auto found = m_buffers.find(&buffer);
    if (found == m_buffers.end()) return 0;
    const BufferMirror& m = found->second;
    const bool current = m.device_newer || m.version == buffer.version();
    return current && m.memory.size() == buffer.count() * buffer.element().size ? m.memory.ptr()
                                                                                : 0;
}

std::vector<std::shared_ptr<const Buffer>> GpuScene::device_newer_buffers() const {
    std::vector<std::shared_ptr<const Buffer>> newer;
    for (const auto& [raw, mirror] : m_buffers)
        if (mirror.device_newer) newer.push_back(mirror.buffer);
    return newer;
}

void GpuScene::fetch(const Buffer& buffer) {
    auto found = m_buffers.find(&buffer);
    if (found != m_buffers.end() && found->second.device_newer) fetch_mirror(found->second);
}

/// The triangles of each instance of a triangles-only group as its buffers hold them, already
/// on the device (flatten_instances mirrored them): a GPU build reads them there (gathered
/// into one mesh on the GPU when there are several), instead of the host gathering and
/// uploading the same bytes. None when an instance's triangles are not its buffers' plain
/// contents (float3 vertices, uint3 indices, from their starts): the host gathers those.
std::optional<std::vector<DeviceTriangles>> GpuScene::mirrored_triangles(
    const core::CompiledScene& scene, const core::CompiledNode& node) {
    std::vector<DeviceTriangles> pieces;
    pieces.reserve(node.instances.size());
    for (unsigned i : node.instances) {
        const core::CompiledInstance& inst = scene.instances[i];
        const GeometryTriangles* tris = inst.triangle_geometry();
        if (!tris || !tris->vertices()) return std::nullopt;
        const Buffer& vertices = *tris->vertices();
        const Buffer* indices = tris->indices().get();
        const unsigned triangles = indices ? unsigned(indices->count())
                                           : unsigned(vertices.count() / 3);
        if (inst.vertices != vertices.raw() || vertices.element().size != sizeof(float3) ||
            inst.primitive_count != triangles ||
            (indices && (inst.indices != indices->raw() ||
                         indices->element().size != sizeof(uint3))))
            return std::nullopt;
        DeviceTriangles d;
        d.positions = device_pointer(tris->vertices());
        d.vertex_count = unsigned(vertices.count());
        d.indices = indices ? device_pointer(tris->indices()) : 0;
        d.triangle_count = triangles;
        pieces.push_back(d);
    }
    return pieces;
}

namespace {

/// Spatial splits put a triangle in several leaves: not where an any-hit program must see
/// each triangle once per ray (TriangleAccel's rule, core/accel_builder.cpp).
bool spatial_splits_allowed(const core::CompiledNode& node) {
    return std::none_of(node.any_hit_enforced_for_ray_type.begin(),
                        node.any_hit_enforced_for_ray_type.end(),
                        [](bool any_hit) { return any_hit; });
}

/// LUCENT_GPU_TREE_UPGRADES=background|sync|off, else the context's choice.
TreeUpgrades upgrades_mode(TreeUpgrades chosen) {
    const char* env = std::getenv("LUCENT_GPU_TREE_UPGRADES");
    if (!env || !*env) return chosen;
    const std::string mode = env;
    if (mode == "background") return TreeUpgrades::kBackground;
    if (mode == "sync") return TreeUpgrades::kWithBuild;
    if (mode == "off") return TreeUpgrades::kOff;
    throw Error("LUCENT_GPU_TREE_UPGRADES=" + mode + ": expected background, sync or off");
}

}  // namespace

/// Queues the upgrade of a group's GPU-built tree (TreeUpgrader): the host's tree with spatial
/// splits, Builder::kBinnedSah's. With TreeUpgrades::kWithBuild it is waited for and adopted.
void GpuScene::start_upgrade(const core::CompiledNode& node, GeometryMirror& mirror) {
    const TreeUpgrades mode = upgrades_mode(m_upgrades);
    if (mode == TreeUpgrades::kOff || mirror.upgrades_off) return;
    if (!m_upgrader) m_upgrader = std::make_unique<TreeUpgrader>(m_context);
    GpuBvhBuildOptions options;
    options.spatial_splits = true;
    try {
        m_upgrader->submit(node.geometry.get(), mirror.version, mirror.bvh, options);
    } catch (const Error&) {
        mirror.upgrades_off = true;  // no memory for the copy: the GPU tree serves
        return;
    }
    mirror.upgrade_pending = true;
    if (mode == TreeUpgrades::kWithBuild) {
        m_upgrader->wait_idle();
        m_upgraded_in_update += adopt_tree_upgrades();
    }
}

unsigned GpuScene::adopt_tree_upgrades() {
    if (!m_upgrader) return 0;
    unsigned adopted = 0;
    for (TreeUpgrader::Finished& done : m_upgrader->take_finished()) {
        const auto found = m_geometry.find(static_cast<const core::GeometryAccel*>(done.group));
        if (found == m_geometry.end()) continue;  // the group is gone
        GeometryMirror& mirror = found->second;
        if (!mirror.upgrade_pending || mirror.version != done.version) continue;  // rebuilt since
        mirror.upgrade_pending = false;
        if (done.tree.nodes.empty()) {
            mirror.upgrades_off = true;  // it keeps the GPU's tree, which traces correctly
            if (std::getenv("LUCENT_GPU_ACCEL_TIMES"))
                std::fprintf(stderr, "lucent: tree upgrade failed: %s\n", done.error.c_str());
            continue;
        }
        upload_gpu_triangle_bvh(done.tree, mirror.bvh);
        mirror.version = ++m_last_version;
        ++adopted;
        if (std::getenv("LUCENT_GPU_ACCEL_TIMES"))
            std::fprintf(stderr,
                         "lucent: tree upgraded: %zu triangle slots, host build %.3f ms, "
                         "conversion %.3f ms, ready %.3f ms after the GPU build\n",
                         done.tree.triangle_ids.size(), done.tree.stats.build_ms,
                         done.tree.stats.convert_ms, done.ready_ms);
    }
    return adopted;
}

/// Rebuilds (or refits) the GPU layout of a GeometryGroup's triangles when they changed:
/// on the GPU for Builder::kAuto (binned SAH) and kGpuHploc, on the host for kBinnedSah.
/// `on_device`: the instances' triangles already in device memory, if they are (no upload).
void GpuScene::update_triangle_bvh(const core::CompiledScene& scene,
                                   const core::CompiledNode& node,
                                   const std::optional<std::vector<DeviceTriangles>>& on_device,
                                   GeometryMirror& mirror) {
    const core::GeometryAccel& ga = *node.geometry;
    if (mirror.structure == ga.structure_signature && mirror.content == ga.content_signature)
        return;
    const auto start = std::chrono::steady_clock::now();
    // A new tree: an upgrade of the old one still building is of no use, and the group's
    // triangles most likely change every frame.
    if (mirror.upgrade_pending) mirror.upgrades_off = true;
    mirror.upgrade_pending = false;
    mirror.version = ++m_last_version;
    // The triangles as one mesh on the host: the compile's when it gathered them (a host
    // build), else gathered here (triangles the device cannot read in place, the host
    // build after a GPU tree too deep).
    std::vector<float3> gathered_vertices;
    std::vector<uint3> gathered_indices;
    auto host_mesh = [&]() -> std::pair<std::span<const float3>, std::span<const uint3>> {
        if (ga.host_triangles) return {ga.vertices, ga.indices};
        if (gathered_indices.empty() && ga.triangle_count > 0)
            core::gather_triangles(scene, node, gathered_vertices, gathered_indices);
        return {gathered_vertices, gathered_indices};
    };
    const Acceleration& accel = acceleration_of(node);
    if (accel.builder() == Builder::kGpuHploc || accel.builder() == Builder::kAuto) {
        if (!m_bvh_builder) {
            m_bvh_builder = m_builder_on_the_way.valid() ? m_builder_on_the_way.get()
                                                         : std::make_unique<GpuBvhBuilder>(m_sm);
            if (std::getenv("LUCENT_GPU_ACCEL_TIMES"))
                std::fprintf(stderr, "lucent: GPU BVH builder ready after %.3f ms\n",
                             std::chrono::duration<double, std::milli>(
                                 std::chrono::steady_clock::now() - start)
                                 .count());
        }
        std::optional<DeviceTriangles> mesh;
        if (on_device && on_device->size() == 1)
            mesh = on_device->front();
        else if (on_device)
            mesh = m_bvh_builder->gather(*on_device);
        const bool refit = mirror.structure == ga.structure_signature && accel.refit() &&
                           mirror.bvh.triangle_count == ga.triangle_count;
        if (refit && mesh) {
            m_bvh_builder->refit(*mesh, mirror.bvh);
        } else if (refit) {
            const auto [vertices, indices] = host_mesh();
            m_bvh_builder->refit(vertices, indices, mirror.bvh);
        } else {
            try {
                GpuBvhBuildOptions options;
                if (accel.builder() == Builder::kGpuHploc)
                    options.gpu_algorithm = GpuBuildAlgorithm::kHploc;
                if (mesh) {
                    m_bvh_builder->build(*mesh, mirror.bvh, options);
                } else {
                    const auto [vertices, indices] = host_mesh();
                    m_bvh_builder->build(vertices, indices, mirror.bvh, options);
                }
                if (accel.builder() == Builder::kAuto && !accel.refit() &&
                    spatial_splits_allowed(node) && ga.triangle_count > 1)
                    start_upgrade(node, mirror);
            } catch (const GpuBvhTooDeep&) {
                // A chain of clusters deeper than the traversal stack: the host SAH build
                // bounds its depth. Without spatial splits it has one reference per
                // triangle, so the refits that follow keep its topology.
                const auto [vertices, indices] = host_mesh();
                GpuBvhBuildOptions host;
                host.spatial_splits = false;
                upload_gpu_triangle_bvh(build_gpu_triangle_bvh(vertices, indices, host),
                                        mirror.bvh);
            }
        }
    } else {
        // Builder::kBinnedSah, the traversal-first build: spatial splits as TriangleAccel
        // gets them (core/accel_builder.cpp), unless an any-hit program must see each
        // triangle once per ray.
        const auto [vertices, indices] = host_mesh();
        GpuBvhBuildOptions host;
        host.spatial_splits = spatial_splits_allowed(node);
        upload_gpu_triangle_bvh(build_gpu_triangle_bvh(vertices, indices, host), mirror.bvh);
    }
    mirror.empty = ga.triangle_count == 0;
    mirror.structure = ga.structure_signature;
    mirror.content = ga.content_signature;
    m_accel_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace lucent::cuda

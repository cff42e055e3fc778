// Scene compilation: graph discovery, checks, program binding (see scene_compiler.h).
#include "core/scene_compiler.h"

#include "core/builtin_geometry.h"
#include "core/launch_buffers.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace lucent::core {

namespace {

std::string ray_type_label(const ContextState& s, unsigned r) {
    return "ray type " + std::to_string(r) + " ('" + s.ray_types[r].name + "')";
}

using runtime::invert_affine;

/// Appends `values` to the scene's motion array; returns where they start.
unsigned append_motion(CompiledScene& scene, const float* values, size_t count) {
    const unsigned offset = unsigned(scene.motion.size());
    scene.motion.insert(scene.motion.end(), values, values + count);
    return offset;
}

/// A motion Transform's keys into the scene: each key must be invertible.
void compile_transform_motion(const Transform& t, CompiledScene& scene, CompiledNode& c) {
    const std::vector<float>& keys = t.motion_keys();
    const unsigned count = t.motion_key_count();
    const bool srt = t.motion() == TransformMotion::kSrt;
    for (unsigned k = 0; k < count; ++k) {
        Matrix4x3 key, inverse;
        if (srt)
            key = runtime::srt_to_matrix(
                runtime::srt_at(keys.data(), std::min(k, count - 2), k == count - 1 ? 1.0f : 0.0f));
        else
            std::copy(keys.begin() + 12 * k, keys.begin() + 12 * (k + 1), key.m);
        if (!invert_affine(key, inverse))
            throw Error(t.describe() + ": motion key " + std::to_string(k) +
                        " is singular (scale 0?); give invertible keys");
        if (k == 0) c.to_world = key, c.to_object = inverse;
    }
    const MotionOptions& o = t.motion_options();
    c.motion.kind = srt ? runtime::kMotionSrt : runtime::kMotionMatrix;
    c.motion.keys = count;
    c.motion.flags = o.flags;
    c.motion.time_begin = o.time_begin;
    c.motion.time_end = o.time_end;
    c.motion.offset = append_motion(scene, keys.data(), keys.size());
}

/// A built-in primitive's motion keys (vertices or centres) into the scene: every key as
/// long as the first, every coordinate finite.
void compile_geometry_motion(const GeometryBase& g, CompiledScene& scene, CompiledInstance& out) {
    const auto& buffers = g.motion_buffers();
    if (buffers.empty()) return;
    const size_t points = buffers[0]->count();
    std::vector<float> flat;
    flat.reserve(points * 3 * buffers.size());
    for (size_t k = 0; k < buffers.size(); ++k) {
        if (buffers[k]->count() != points)
            throw Error(g.describe() + ": motion key " + std::to_string(k) + " has " +
                        std::to_string(buffers[k]->count()) + " points but key 0 has " +
                        std::to_string(points) + "; give every key the same count");
        const float3* p = buffers[k]->data<float3>();
        for (size_t i = 0; i < points; ++i) {
            if (!std::isfinite(p[i].x) || !std::isfinite(p[i].y) || !std::isfinite(p[i].z))
                throw Error(g.describe() + ": point " + std::to_string(i) + " of motion key " +
                            std::to_string(k) + " is not finite; fix the key's buffer");
            flat.insert(flat.end(), {p[i].x, p[i].y, p[i].z});
        }
    }
    const MotionOptions& o = g.motion_options();
    out.motion.kind = runtime::kMotionVertices;
    out.motion.keys = unsigned(buffers.size());
    out.motion.flags = o.flags;
    out.motion.time_begin = o.time_begin;
    out.motion.time_end = o.time_end;
    out.motion.offset = append_motion(scene, flat.data(), flat.size());
    out.motion_points = unsigned(points);
}
}  // namespace

std::unique_ptr<CompiledScene> SceneCompiler::compile() {
    compile_graph();
    build_accelerations();
    for (const Buffer* b : m_rebuild_inputs) m_scene->rebuild_inputs.emplace_back(b, b->version());
    for (unsigned e = 0; e < m_scene->entries.size(); ++e) {
        std::set<const Buffer*> written;
        for_each_program(*m_scene, e, [&](const CompiledProgram& p) {
            for (const auto& b : p.writable_buffers) written.insert(b.get());
        });
        m_scene->entries[e].written_buffers.assign(written.begin(), written.end());
    }
    return std::move(m_scene);
}

void SceneCompiler::validate_only() {
    compile_graph();
}

void SceneCompiler::compile_graph() {
    m_scene = std::make_unique<CompiledScene>();
    CompiledScene& scene = *m_scene;
    scene.max_depth = m_state.max_depth;
    scene.print_enabled = m_state.print_enabled;
    scene.print_index = m_state.print_index;
    scene.enabled_exceptions = m_state.enabled_exceptions;
    for (const ContextModule& module : m_state.modules)
        if (module.source) scene.module_sources[module.info] = module.source;

    for (unsigned r = 0; r < m_state.ray_types.size(); ++r)
        if (!m_state.ray_types[r].payload)
            throw Error("Context: ray type " + std::to_string(r) +
                        " is not declared but a higher one is; ray types are numbered 0, 1, ... "
                        "without gaps: declare it with set_ray_type<Payload>(" +
                        std::to_string(r) + ", name)");
    scene.ray_types = m_state.ray_types;

    ScopeChain context_scope;
    context_scope.then(m_state.context);
    for (unsigned e = 0; e < m_state.entries.size(); ++e) {
        CompiledEntry entry;
        const std::string owner = "entry point " + std::to_string(e);
        entry.ray_generation =
            pack(m_state.entries[e].ray_generation, context_scope, owner, &entry.output_buffers);
        entry.exception = pack(m_state.entries[e].exception, context_scope, owner);
        scene.entries.push_back(std::move(entry));
    }
    for (unsigned r = 0; r < m_state.ray_types.size(); ++r)
        scene.miss.push_back(pack(m_state.miss[r], context_scope, ray_type_label(m_state, r)));

    for (const RayTypeDesc& r : m_state.ray_types)
        for (const auto& root : r.roots)
            if (root) node_index(root);
    // Nodes are discovered while packing (Handle variables) and compiled breadth-first.
    for (size_t i = 0; i < m_node_queue.size(); ++i) compile_node(m_node_queue[i]);
    check_cycles();
    find_reached_instances();
    check_types();
}

unsigned SceneCompiler::node_index(const std::shared_ptr<Node>& node) {
    auto it = m_node_ids.find(node.get());
    if (it != m_node_ids.end()) return it->second;
    unsigned index = unsigned(m_scene->nodes.size());
    m_node_ids[node.get()] = index;
    m_node_refs.push_back(node);
    CompiledNode compiled;
    compiled.kind = node->kind();
    compiled.source = node.get();
    m_scene->nodes.push_back(std::move(compiled));
    m_node_queue.push_back(index);
    return index;
}

unsigned SceneCompiler::instance_index(const GeometryInstance& instance) {
    auto it = m_instance_ids.find(&instance);
    if (it != m_instance_ids.end()) return it->second;
    unsigned index = unsigned(m_scene->instances.size());
    m_instance_ids[&instance] = index;
    m_scene->instances.emplace_back();
    m_scene->instances.back().source = &instance;
    compile_instance(index);
    return index;
}

void SceneCompiler::compile_node(unsigned index) {
    const Node& node = *m_scene->nodes[index].source;
    m_scene->nodes[index].visibility_mask = node.visibility_mask();
    ScopeChain context_scope;
    context_scope.then(m_state.context);
    switch (node.kind()) {
        case NodeKind::kGroup:
        case NodeKind::kSelector: {
            auto& n = static_cast<const NodeWithChildren&>(node);
            std::vector<unsigned> children;
            for (auto& child : n.children()) children.push_back(node_index(child));
            CompiledNode& c = m_scene->nodes[index];
            c.children = std::move(children);
            if (node.kind() == NodeKind::kGroup) {
                c.brute_force =
                    static_cast<const Group&>(node).acceleration()->builder() == Builder::kNone;
            } else {
                auto& visit = static_cast<const Selector&>(node).visit_program();
                if (!visit)
                    throw Error(node.describe() +
                                " has no visit program; set one with set_visit_program");
                CompiledProgram p = pack(visit, context_scope, node.describe());
                m_scene->nodes[index].visit = std::move(p);
            }
            break;
        }
        case NodeKind::kTransform: {
            auto& t = static_cast<const Transform&>(node);
            if (!t.child())
                throw Error(node.describe() + " has no child; give it one with set_child");
            for (float v : t.matrix().m)
                if (!std::isfinite(v))
                    throw Error(node.describe() +
                                ": the matrix has a non-finite entry (NaN or infinity); "
                                "set a finite affine matrix with set_matrix");
            Matrix4x3 inverse;
            if (!invert_affine(t.matrix(), inverse))
                throw Error(node.describe() +
                            ": the matrix is singular (scale 0?); set an invertible matrix");
            unsigned child = node_index(t.child());
            CompiledNode& c = m_scene->nodes[index];
            c.children = {child};
            c.to_world = t.matrix();
            c.to_object = inverse;
            c.instance_id = t.instance_id();
            if (t.motion() != TransformMotion::kNone) compile_transform_motion(t, *m_scene, c);
            break;
        }
        case NodeKind::kGeometryGroup: {
            auto& g = static_cast<const GeometryGroup&>(node);
            std::vector<unsigned> instances;
            for (auto& gi : g.children()) instances.push_back(instance_index(*gi));
            CompiledNode& c = m_scene->nodes[index];
            c.instances = std::move(instances);
            c.brute_force = g.acceleration()->builder() == Builder::kNone;
            c.any_hit_for_ray_type.assign(m_state.ray_types.size(), false);
            c.any_hit_enforced_for_ray_type.assign(m_state.ray_types.size(), false);
            for (unsigned i : c.instances) {
                const CompiledInstance& inst = m_scene->instances[i];
                c.instances_masked |= inst.visibility_mask != kVisibilityMaskAll;
                for (auto& m : inst.materials)
                    for (unsigned r = 0; r < m.any_hit.size(); ++r)
                        if (m.any_hit[r]) {
                            c.any_hit_enforced_for_ray_type[r] = true;
                            if (!inst.opaque) c.any_hit_for_ray_type[r] = true;
                        }
            }
            break;
        }
    }
}

void SceneCompiler::compile_instance(unsigned index) {
    const GeometryInstance& gi = *m_scene->instances[index].source;
    if (!gi.geometry()) throw Error(gi.describe() + " has no geometry; set one with set_geometry");
    if (gi.material_count() == 0)
        throw Error(gi.describe() + " has no material; add one with add_material");
    const GeometryBase& geometry = *gi.geometry();
    CompiledInstance out;
    out.source = &gi;
    out.type = geometry.primitive_type();
    out.primitive_count = geometry.primitive_count();
    out.opaque = geometry.flags() & kGeometryFlagDisableAnyHit;
    out.visibility_mask = gi.visibility_mask();
    out.user_id = gi.instance_id();

    ScopeChain geometry_scope;
    geometry_scope.then(&gi).then(&geometry).then(m_state.context);
    if (out.type == PrimitiveType::kTriangles) {
        auto& tris = static_cast<const GeometryTriangles&>(geometry);
        bind_triangles(tris, gi, out);
        out.attribute = pack(tris.attribute_program(), geometry_scope, gi.describe());
        out.attributes =
            out.attribute ? out.attribute.desc->attributes : &type_info_of<TriangleAttributes>();
    } else if (out.type == PrimitiveType::kSpheres) {
        bind_spheres(static_cast<const GeometrySpheres&>(geometry), gi, out);
        out.attributes = &type_info_of<BuiltinSphereAttributes>();
    } else if (out.type == PrimitiveType::kCurves) {
        bind_curves(static_cast<const GeometryCurves&>(geometry), gi, out);
        out.attributes = &type_info_of<BuiltinCurveAttributes>();
    } else {
        auto& custom = static_cast<const Geometry&>(geometry);
        if (!custom.intersection_program())
            throw Error(custom.describe() +
                        " has no intersection program; set one with set_intersection_program");
        if (!custom.bounding_box_program())
            throw Error(custom.describe() +
                        " has no bounding-box program; set one with set_bounding_box_program");
        out.intersection = pack(custom.intersection_program(), geometry_scope, gi.describe());
        out.bounding_box = pack(custom.bounding_box_program(), geometry_scope, gi.describe());
        out.attributes = out.intersection.desc->attributes;
    }
    compile_geometry_motion(geometry, *m_scene, out);
    if (out.attributes->size > kMaxAttributeBytes)
        throw Error(gi.describe() + ": attribute type " + std::string(out.attributes->name) +
                    " is " + std::to_string(out.attributes->size) + " bytes; the engine allows " +
                    std::to_string(kMaxAttributeBytes) + ": keep attributes small");

    ScopeChain material_scope;
    for (unsigned m = 0; m < gi.material_count(); ++m) {
        const auto& material = gi.material(m);
        if (!material)
            throw Error(gi.describe() + ": material " + std::to_string(m) +
                        " is not set; set it with set_material");
        material_scope = ScopeChain{};
        material_scope.then(&gi).then(material.get()).then(m_state.context);
        for (unsigned r = unsigned(m_state.ray_types.size()); r < material->ray_type_slots(); ++r)
            if (material->closest_hit(r) || material->any_hit(r))
                throw Error(material->describe() + " has a program for ray type " +
                            std::to_string(r) + ", which is not declared (the context has " +
                            std::to_string(m_state.ray_types.size()) +
                            "); declare it with set_ray_type<Payload>(" + std::to_string(r) +
                            ", name)");
        CompiledMaterial cm;
        for (unsigned r = 0; r < m_state.ray_types.size(); ++r) {
            std::string owner = material->describe() + " for " + ray_type_label(m_state, r) +
                                " in " + gi.describe();
            cm.closest_hit.push_back(pack(material->closest_hit(r), material_scope, owner));
            cm.any_hit.push_back(pack(material->any_hit(r), material_scope, owner));
        }
        out.materials.push_back(std::move(cm));
    }
    m_scene->instances[index] = std::move(out);
}

void SceneCompiler::check_cycles() const {
    // Depth-first search over child edges: 0 unvisited, 1 on the path, 2 done.
    const auto& nodes = m_scene->nodes;
    std::vector<int> state(nodes.size(), 0);
    std::vector<unsigned> path;
    auto visit = [&](auto&& self, unsigned n) -> void {
        state[n] = 1;
        path.push_back(n);
        for (unsigned c : nodes[n].children) {
            if (state[c] == 1) {
                std::string cycle;
                bool in = false;
                for (unsigned p : path) {
                    in = in || p == c;
                    if (in) cycle += nodes[p].source->describe() + " -> ";
                }
                throw Error("the scene graph has a cycle: " + cycle + nodes[c].source->describe() +
                            "; a node may not be its own descendant (remove one of these edges)");
            }
            if (state[c] == 0) self(self, c);
        }
        path.pop_back();
        state[n] = 2;
    };
    for (unsigned n = 0; n < nodes.size(); ++n)
        if (state[n] == 0) visit(visit, n);
}

void SceneCompiler::find_reached_instances() {
    const CompiledScene& scene = *m_scene;
    m_reaches.assign(scene.ray_types.size(), {});
    for (unsigned r = 0; r < scene.ray_types.size(); ++r) {
        if (scene.ray_types[r].roots.empty()) continue;
        std::vector<bool> reached(scene.instances.size(), false), seen(scene.nodes.size(), false);
        std::vector<unsigned> stack;
        for (const auto& root : scene.ray_types[r].roots)
            if (root) stack.push_back(m_node_ids.at(root.get()));
        while (!stack.empty()) {
            unsigned n = stack.back();
            stack.pop_back();
            if (seen[n]) continue;
            seen[n] = true;
            for (unsigned c : scene.nodes[n].children) stack.push_back(c);
            for (unsigned i : scene.nodes[n].instances) reached[i] = true;
        }
        m_reaches[r] = std::move(reached);
    }
}

void SceneCompiler::check_types() const {
    const CompiledScene& scene = *m_scene;
    auto payload_check = [&](const CompiledProgram& p, unsigned r) {
        if (p && !same_type(*p.desc->payload, *scene.ray_types[r].payload))
            throw Error(p.label + ": its payload type is " + std::string(p.desc->payload->name) +
                        " but " + ray_type_label(m_state, r) + " carries " +
                        std::string(scene.ray_types[r].payload->name) +
                        "; make the program take that payload, or bind it to another ray type");
    };
    for (unsigned r = 0; r < scene.miss.size(); ++r) payload_check(scene.miss[r], r);
    for (const CompiledInstance& inst : scene.instances) {
        for (unsigned m = 0; m < inst.materials.size(); ++m) {
            const CompiledMaterial& mat = inst.materials[m];
            for (unsigned r = 0; r < scene.ray_types.size(); ++r) {
                for (const CompiledProgram* p : {&mat.closest_hit[r], &mat.any_hit[r]}) {
                    payload_check(*p, r);
                    if (*p && !same_type(*p->desc->attributes, *inst.attributes))
                        throw Error(p->label + ": it reads attributes " +
                                    std::string(p->desc->attributes->name) + " but " +
                                    inst.source->geometry()->describe() + " reports " +
                                    std::string(inst.attributes->name) +
                                    "; use the same attribute type in the intersection (or "
                                    "attribute) program and the hit programs");
                }
                const size_t self = size_t(&inst - scene.instances.data());
                const bool reached = m_reaches[r].empty() || m_reaches[r][self];
                if (scene.ray_types[r].expects_closest_hit && reached && !mat.closest_hit[r])
                    throw Error(
                        inst.source->material(m)->describe() + " in " + inst.source->describe() +
                        " has no closest-hit program for " + ray_type_label(m_state, r) +
                        ", which reaches it; bind one with set_closest_hit(" + std::to_string(r) +
                        ", program), declare the ray type with expects_closest_hit = false "
                        "if it only needs any-hit, or name the graphs it traces as its roots");
            }
        }
    }
}

}  // namespace lucent::core

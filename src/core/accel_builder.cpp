// Acceleration structures of the compiled scene: GeometryGroups are built (or refitted)
// only when what they are made of changed; Groups are rebuilt each compile (few children).
#include <algorithm>
#include <chrono>
#include <cstring>
#include <set>

#include "core/program_exception.h"
#include "lucent/device/curve_intersect.h"
#include "core/scene_compiler.h"
#include "core/triangle_gather.h"

namespace lucent::core {

namespace {
struct Hasher {  // FNV-1a over the bytes of the values that define an acceleration
    uint64_t h = 1469598103934665603ull;
    template <class T>
    Hasher& add(const T& v) {
        const unsigned char* p = reinterpret_cast<const unsigned char*>(&v);
        for (size_t i = 0; i < sizeof(T); ++i) h = (h ^ p[i]) * 1099511628211ull;
        return *this;
    }
    Hasher& add_bytes(const void* data, size_t n) {
        const unsigned char* p = static_cast<const unsigned char*>(data);
        for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
        return *this;
    }
};

Aabb empty_box() {
    return Aabb{make_float3(kInfinity), make_float3(-kInfinity)};
}
void grow(Aabb& b, float3 p) {
    b.lo = fminf(b.lo, p);
    b.hi = fmaxf(b.hi, p);
}
void grow(Aabb& b, const Aabb& o) {
    b.lo = fminf(b.lo, o.lo);
    b.hi = fmaxf(b.hi, o.hi);
}
bool is_empty(const Aabb& b) {
    return b.lo.x > b.hi.x;
}

/// The box of a moving triangle or sphere over its whole time range: the union of its keys'
/// boxes holds it, since each point moves linearly between keys (OptiX's motion AABBs are
/// per key; one box over all of them trades some culling for one BVH of the usual kind).
Aabb motion_primitive_box(const CompiledInstance& inst, const float* motion, unsigned prim) {
    Aabb box = empty_box();
    const runtime::MotionRange& m = inst.motion;
    for (unsigned k = 0; k < m.keys; ++k) {
        // Key k is (k - 1, frac 1) for the last one.
        const unsigned key = k + 1 < m.keys ? k : k - 1;
        const float frac = k + 1 < m.keys ? 0.0f : 1.0f;
        auto point = [&](unsigned i) {
            return runtime::motion_point(motion, m, inst.motion_points, i, key, frac);
        };
        if (inst.triangles()) {
            const uint3 t = inst.triangle(prim);
            grow(box, point(t.x));
            grow(box, point(t.y));
            grow(box, point(t.z));
        } else {
            const float3 c = point(prim), r = make_float3(inst.radius(prim));
            grow(box, Aabb{c - r, c + r});
        }
    }
    return box;
}

Aabb primitive_box(const CompiledInstance& inst, const float* motion, unsigned prim) {
    if (runtime::moving(inst.motion)) return motion_primitive_box(inst, motion, prim);
    Aabb box = empty_box();
    if (inst.triangles()) {
        uint3 t = inst.triangle(prim);
        grow(box, inst.vertices[t.x]);
        grow(box, inst.vertices[t.y]);
        grow(box, inst.vertices[t.z]);
    } else if (inst.type == PrimitiveType::kSpheres) {
        const float3 c = inst.centers[prim], r = make_float3(inst.radius(prim));
        box = Aabb{c - r, c + r};
    } else if (inst.type == PrimitiveType::kCurves) {
        // Reference `prim` boxes its part of a segment: the part's Bezier points hold it
        // (convex hull), widened by the largest of their radii and by a few roundings of
        // the hull's arithmetic (relative, 2^-20 of the largest coordinate).
        const unsigned references = curve_references(inst.curve_type);
        const unsigned segment = prim / references, part = prim % references;
        CurvePoint b[4], hull[4];
        load_curve_segment(inst.curve_type, inst.vertices, inst.radii, inst.segments[segment], b);
        const float pieces = float(curve_pieces(inst.curve_type));
        const int per_reference = curve_pieces(inst.curve_type) / int(references);
        const float u0 = float(int(part) * per_reference) / pieces;
        const float u1 = part + 1 == references ? 1.0f : float(int(part + 1) * per_reference) / pieces;
        curve_part_hull(b, u0, u1, hull);
        float radius = 0.0f, extent = 0.0f;
        for (const CurvePoint& q : hull) {
            grow(box, make_float3(q));
            radius = std::max(radius, std::fabs(q.w));
            extent = std::max({extent, std::fabs(q.x), std::fabs(q.y), std::fabs(q.z)});
        }
        const float pad = radius + extent * 0x1p-20f;
        box.lo = box.lo - make_float3(pad);
        box.hi = box.hi + make_float3(pad);
    } else {
        try {
            inst.bounding_box.entry<BoundingBoxFn>()(inst.bounding_box.rec(), prim, box);
        } catch (const ProgramException& e) {
            throw Error(inst.bounding_box.label + " raised " + exception_name(e.code) +
                        " (detail " + std::to_string(e.detail) + ") for primitive " +
                        std::to_string(prim) +
                        "; check the primitive count against the buffers it reads");
        }
    }
    return box;
}

/// The box of `child` moved by `m`: the box of its eight corners.
Aabb transformed_box(const Matrix4x3& m, const Aabb& child) {
    Aabb box = empty_box();
    for (int c = 0; c < 8; ++c)
        grow(box, transform_point(m, make_float3(c & 1 ? child.hi.x : child.lo.x,
                                                 c & 2 ? child.hi.y : child.lo.y,
                                                 c & 4 ? child.hi.z : child.lo.z)));
    return box;
}

/// The box of `child` under a motion transform, over the whole time range (OptiX's motion
/// transforms are bounded the same way for the instance above them).
/// Matrix keys: between two keys every point moves linearly (M(t) x is linear in t), so the
/// union of the keys' transformed boxes holds it exactly enough.
/// SRT keys: S(t) and T(t) are linear, but the rotation of the normalised quaternion is not.
/// Per key interval: when both keys have the same quaternion, R is fixed and the union of
/// the two keys' boxes holds it as above. Otherwise, conservatively: S(t) x lies in the
/// union B of the box moved by the two keys' S; a rotation keeps |y|, so R(t) S(t) x lies in
/// the ball of radius max |corner of B| about the origin; then T(t) adds the box of the two
/// translations.
Aabb motion_transform_bounds(const runtime::MotionRange& m, const float* motion,
                             const Aabb& child) {
    Aabb box = empty_box();
    const float* keys = motion + m.offset;
    for (unsigned k = 0; k + 1 < m.keys; ++k) {
        if (m.kind == runtime::kMotionMatrix) {
            for (unsigned j = k; j <= k + 1; ++j) {
                Matrix4x3 key;
                std::memcpy(key.m, keys + 12 * j, sizeof key.m);
                grow(box, transformed_box(key, child));
            }
            continue;
        }
        const float* a = keys + 16 * k;
        const float* b = a + 16;
        if (std::memcmp(a + 9, b + 9, 4 * sizeof(float)) == 0) {
            for (float frac : {0.0f, 1.0f})
                grow(box, transformed_box(runtime::srt_to_matrix(runtime::srt_at(keys, k, frac)),
                                          child));
            continue;
        }
        float radius = 0.0f;
        for (const float* key : {a, b}) {
            Matrix4x3 s{};  // S alone: the scale/shear with the pivot
            const float entries[12] = {key[0], key[1], key[2], key[3], 0.0f,   key[4],
                                       key[5], key[6], 0.0f,   0.0f,   key[7], key[8]};
            std::memcpy(s.m, entries, sizeof s.m);
            const Aabb scaled = transformed_box(s, child);
            for (int c = 0; c < 8; ++c)
                radius = std::max(radius, length(make_float3(c & 1 ? scaled.hi.x : scaled.lo.x,
                                                             c & 2 ? scaled.hi.y : scaled.lo.y,
                                                             c & 4 ? scaled.hi.z : scaled.lo.z)));
        }
        radius *= 1.0f + 0x1p-20f;  // the rotation's roundings
        for (const float* key : {a, b}) {
            const float3 t = make_float3(key[13], key[14], key[15]);
            grow(box, Aabb{t - make_float3(radius), t + make_float3(radius)});
        }
    }
    return box;
}
}  // namespace

void SceneCompiler::build_geometry_accel(CompiledNode& node) {
    auto* group = static_cast<const GeometryGroup*>(node.source);
    Acceleration& accel = *group->acceleration();
    auto& cached = m_cache[group];
    if (!cached) cached = std::make_shared<GeometryAccel>();
    GeometryAccel& ga = *cached;

    Hasher structure, content;
    bool triangles_only = !node.instances.empty();
    for (unsigned i : node.instances) {
        const CompiledInstance& inst = m_scene->instances[i];
        structure.add(inst.source).add(inst.type).add(inst.primitive_count).add(inst.bvh_references());
        // Moving primitives go through the generic BVH, boxed over their keys.
        structure.add(inst.motion.kind).add(inst.motion.keys);
        if (runtime::moving(inst.motion)) {
            triangles_only = false;
            for (const auto& b : inst.source->geometry()->motion_buffers()) {
                content.add(b.get()).add(b->version());
                m_rebuild_inputs.push_back(b.get());
            }
        }
        if (const GeometryTriangles* tris = inst.triangle_geometry()) {
            structure.add(tris->indices().get())
                .add(tris->indices() ? tris->indices()->version() : 0);
            content.add(tris->vertices().get()).add(tris->vertices()->version());
            m_rebuild_inputs.push_back(tris->vertices().get());
            if (tris->indices()) m_rebuild_inputs.push_back(tris->indices().get());
        } else if (inst.type == PrimitiveType::kSpheres) {
            triangles_only = false;
            auto& spheres = static_cast<const GeometrySpheres&>(*inst.source->geometry());
            for (const Buffer* b : {spheres.centers().get(), spheres.radii().get()}) {
                content.add(b).add(b->version());
                m_rebuild_inputs.push_back(b);
            }
        } else if (inst.type == PrimitiveType::kCurves) {
            triangles_only = false;
            auto& curves = static_cast<const GeometryCurves&>(*inst.source->geometry());
            content.add(unsigned(curves.curve_type()));
            for (const Buffer* b : {curves.vertices().get(), curves.radii().get(),
                                    curves.segment_indices().get()}) {
                content.add(b).add(b->version());
                m_rebuild_inputs.push_back(b);
            }
        } else {
            triangles_only = false;
            content.add_bytes(inst.bounding_box.rec(), inst.bounding_box.desc->record->size);
            for (const auto& b : inst.bounding_box.buffers) {
                content.add(b.get()).add(b->version());
                m_rebuild_inputs.push_back(b.get());
            }
        }
    }
    structure.add(accel.builder());
    // Spatial splits may put a triangle in several leaves, and an any-hit program would then
    // be offered it more than once per ray: only groups without any-hit programs get them
    // (opaque geometry's count: kRayFlagEnforceAnyHit runs them).
    bool any_hit = false;
    for (bool a : node.any_hit_enforced_for_ray_type) any_hit = any_hit || a;
    structure.add(any_hit);
    const bool same_structure = ga.structure_signature == structure.h;
    const bool same_content = ga.content_signature == content.h;
    node.geometry = cached;
    // A BVH built on the GPU needs no host copy unless the host traverses too.
    const bool host_triangles = m_host_traversal || (accel.builder() != Builder::kGpuHploc &&
                                                     accel.builder() != Builder::kAuto);
    const bool host_current = ga.host_triangles || !host_triangles || !ga.triangles_only;
    if (same_structure && same_content && !accel.dirty() && host_current) return;
    const bool refit = same_structure && accel.refit() && !node.brute_force && host_current;

    // Gather primitives: global reference = prim_first[instance] + local index.
    ga.triangles_only = triangles_only && !node.brute_force;
    ga.prim_first.clear();
    uint32_t total = 0;
    for (unsigned i : node.instances) {
        ga.prim_first.push_back(total);
        total += m_scene->instances[i].bvh_references();
    }
    if (ga.triangles_only) {
        ga.triangle_count = total;
        if (!host_triangles) {
            // The GPU gathers the triangles itself (GpuScene); the scene above needs only
            // their bounds.
            ga.vertices.clear();
            ga.indices.clear();
            ga.tri_instance.clear();
            ga.triangles = accel::TriangleAccel();
            ga.bounds = triangle_bounds(*m_scene, node);
        } else {
            gather_triangles(*m_scene, node, ga.vertices, ga.indices, &ga.tri_instance);
            accel::BuildOptions options;
            options.spatial_splits = !any_hit;
            if (refit)
                ga.triangles.refit(ga.vertices, ga.indices);
            else
                ga.triangles.build(ga.vertices, ga.indices, options);
            ga.bounds = ga.triangles.triangle_count() ? ga.triangles.bounds() : empty_box();
        }
        ga.host_triangles = host_triangles;
    } else {
        ga.triangle_count = 0;
        std::vector<Aabb> boxes;
        boxes.reserve(total);
        Aabb all = empty_box();
        for (unsigned i : node.instances) {
            const CompiledInstance& inst = m_scene->instances[i];
            for (unsigned p = 0; p < inst.bvh_references(); ++p) {
                boxes.push_back(primitive_box(inst, m_scene->motion.data(), p));
                if (!is_empty(boxes.back())) grow(all, boxes.back());
            }
        }
        if (refit)
            ga.bvh.refit(boxes);
        else
            ga.bvh.build(boxes);
        ga.bounds = all;
    }
    ga.structure_signature = structure.h;
    ga.content_signature = content.h;
}

Aabb SceneCompiler::node_bounds(unsigned index, std::vector<int>& state) {
    CompiledNode& node = m_scene->nodes[index];
    if (state[index] == 2) return node.bounds;
    Aabb box = empty_box();
    switch (node.kind) {
        case NodeKind::kGeometryGroup:
            build_geometry_accel(node);
            box = node.geometry->bounds;
            break;
        case NodeKind::kTransform: {
            Aabb child = node_bounds(node.children[0], state);
            if (!is_empty(child))
                box = runtime::moving(node.motion)
                          ? motion_transform_bounds(node.motion, m_scene->motion.data(), child)
                          : transformed_box(node.to_world, child);
            break;
        }
        case NodeKind::kGroup:
        case NodeKind::kSelector: {
            std::vector<Aabb> boxes;
            for (unsigned c : node.children) {
                boxes.push_back(node_bounds(c, state));
                if (!is_empty(boxes.back())) grow(box, boxes.back());
            }
            if (node.kind == NodeKind::kGroup && !node.brute_force) node.child_bvh.build(boxes);
            break;
        }
    }
    node.bounds = box;
    state[index] = 2;
    return box;
}

void SceneCompiler::build_accelerations() {
    auto t0 = std::chrono::steady_clock::now();
    std::vector<int> state(m_scene->nodes.size(), 0);
    for (unsigned n = 0; n < m_scene->nodes.size(); ++n) node_bounds(n, state);
    std::set<const GeometryGroup*> used;
    for (const CompiledNode& node : m_scene->nodes) {
        if (node.kind == NodeKind::kGeometryGroup) {
            auto* g = static_cast<const GeometryGroup*>(node.source);
            used.insert(g);
            g->acceleration()->clear_dirty();
        } else if (node.kind == NodeKind::kGroup) {
            static_cast<const Group*>(node.source)->acceleration()->clear_dirty();
        }
    }
    for (auto it = m_cache.begin(); it != m_cache.end();)
        it = used.count(it->first) ? std::next(it) : m_cache.erase(it);
    m_accel_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace lucent::core

// The scene graph (OptiX paper §3.2): Group, GeometryGroup, Transform, Selector, and the
// leaves GeometryInstance, Geometry, GeometryTriangles, GeometrySpheres and Material; plus
// Acceleration.
// Nodes may have several parents (instancing); any node may be the root of a trace.
#pragma once

#include <algorithm>
#include <memory>
#include <span>
#include <vector>

#include "lucent/buffer.h"
#include "lucent/object.h"
#include "lucent/program.h"
#include "lucent/variables.h"

namespace lucent {

enum class NodeKind { kGroup, kGeometryGroup, kTransform, kSelector };
const char* node_kind_name(NodeKind kind);

/// How an Acceleration builds its BVH.
enum class Builder {
    // The default: binned SAH (Wald 2007), built where the backend traces: on the CUDA
    // backend on the GPU (bvh_sah_build.cuh: the host's algorithm splitting objects only,
    // 1.1 ms for Sponza on an H200 against 19 ms on the host), then upgraded to kBinnedSah's
    // tree, built on another thread (ContextOptions::tree_upgrades); on the CPU backend (and
    // wherever a CPU device traces too) on the host, as kBinnedSah.
    kAuto,
    // Binned SAH built on the host with spatial splits (Stich et al. 2009) where no any-hit
    // program must see each triangle once: the best traversal (on the GPU Sponza's rays
    // 1.1-1.3x kAuto's, docs/performance.md) for a slower build; rebuilt when marked dirty.
    kBinnedSah,
    kNone,  // no hierarchy: every child or primitive is tested (for tiny sets)
    // Triangles that change every frame: on the CUDA backend the BVH is built on the GPU
    // (H-PLOC, Benthin et al. 2024; build and trace figures in docs/performance.md) and,
    // with set_refit(true), refitted there; the host builds nothing for it unless a CPU
    // device traces the scene too. Elsewhere: binned SAH.
    kGpuHploc,
};

/// The acceleration structure of a Group or GeometryGroup.
class Acceleration : public ContextObject {
  public:
    using ContextObject::ContextObject;
    std::string describe() const override;
    void set_builder(Builder builder);
    Builder builder() const { return m_builder; }
    /// When on, a dirty acceleration whose primitive count is unchanged is refitted
    /// (boxes updated bottom-up) instead of rebuilt: fast for animated vertices.
    void set_refit(bool refit);
    bool refit() const { return m_refit; }
    /// Geometry below changed (e.g. vertices moved): rebuild or refit at the next launch.
    void mark_dirty();
    bool dirty() const { return m_dirty; }
    void clear_dirty() { m_dirty = false; }

  private:
    Builder m_builder = Builder::kAuto;
    bool m_refit = false;
    bool m_dirty = true;
};

class Node : public ContextObject {
  public:
    Node(detail::OwnerRef owner, std::string name, NodeKind kind)
        : ContextObject(std::move(owner), std::move(name)), m_kind(kind) {}
    NodeKind kind() const { return m_kind; }
    std::string describe() const override;
    /// The node's 8-bit visibility mask (default 0xff): a ray whose visibility mask shares no
    /// bit with it skips the node and everything below it (trace()'s `visibility_mask`,
    /// OptiX's OptixInstance::visibilityMask). A mask above 0xff is an error.
    void set_visibility_mask(unsigned mask);
    unsigned visibility_mask() const { return m_visibility_mask; }

  private:
    NodeKind m_kind;
    unsigned m_visibility_mask = kVisibilityMaskAll;
};

/// Child list shared by Group and Selector.
class NodeWithChildren : public Node {
  public:
    using Node::Node;
    /// Appends a child; returns its index.
    unsigned add_child(std::shared_ptr<Node> child);
    void set_child(unsigned index, std::shared_ptr<Node> child);
    void remove_child(unsigned index);
    unsigned child_count() const { return unsigned(m_children.size()); }
    const std::shared_ptr<Node>& child(unsigned index) const;
    const std::vector<std::shared_ptr<Node>>& children() const { return m_children; }

  protected:
    virtual void children_changed() { changed(); }
    std::vector<std::shared_ptr<Node>> m_children;
};

/// Children of any node kind, under an acceleration structure (top of a two-level scene).
class Group : public NodeWithChildren {
  public:
    Group(detail::OwnerRef owner, std::string name, std::shared_ptr<Acceleration> accel)
        : NodeWithChildren(std::move(owner), std::move(name), NodeKind::kGroup),
          m_accel(std::move(accel)) {}
    const std::shared_ptr<Acceleration>& acceleration() const { return m_accel; }
    void set_acceleration(std::shared_ptr<Acceleration> accel);

  protected:
    void children_changed() override;

  private:
    std::shared_ptr<Acceleration> m_accel;
};

/// Children chosen per ray by a visit program.
class Selector : public NodeWithChildren {
  public:
    Selector(detail::OwnerRef owner, std::string name)
        : NodeWithChildren(std::move(owner), std::move(name), NodeKind::kSelector) {}
    void set_visit_program(std::shared_ptr<Program> visit);
    const std::shared_ptr<Program>& visit_program() const { return m_visit; }

  private:
    std::shared_ptr<Program> m_visit;
};

/// The time range of an object's motion keys (OptiX's OptixMotionOptions; the key count is
/// the number of keys given): keys are spaced evenly over [time_begin, time_end], and a ray
/// time outside it sees the first or last key unless `flags` (MotionFlags) say the object
/// vanishes there. time_begin < time_end, both finite.
struct MotionOptions {
    float time_begin = 0.0f;
    float time_end = 1.0f;
    unsigned flags = kMotionFlagNone;
};

/// How a Transform moves its child.
enum class TransformMotion { kNone, kMatrix, kSrt };

/// One child moved by an affine 4x3 matrix (object to world), or by keys over time.
class Transform : public Node {
  public:
    Transform(detail::OwnerRef owner, std::string name);
    void set_child(std::shared_ptr<Node> child);
    const std::shared_ptr<Node>& child() const { return m_child; }
    /// Row-major 3x4 (the last row 0 0 0 1 is implied); `transpose` for column-major input.
    /// Makes the transform static (drops motion keys).
    void set_matrix(const float m[12], bool transpose = false);
    void set_matrix(const Matrix4x3& m) { set_matrix(m.m); }
    const Matrix4x3& matrix() const { return m_matrix; }
    /// A matrix motion transform (OptiX's OptixMatrixMotionTransform): two or more
    /// object-to-world keys over `options`' time range, interpolated entry by entry at the
    /// ray's time (ray_time()) and then inverted. Fewer than two keys, a non-finite entry or
    /// a bad time range is an Error; a singular key is reported at launch.
    void set_motion_matrices(std::span<const Matrix4x3> keys, const MotionOptions& options = {});
    /// A scale-rotation-translation motion transform (OptiX's OptixSRTMotionTransform): two
    /// or more SrtData keys, interpolated per component, the quaternion by normalised linear
    /// interpolation. A key whose quaternion has length 0 is an Error, as above.
    void set_motion_srt(std::span<const SrtData> keys, const MotionOptions& options = {});
    TransformMotion motion() const { return m_motion; }
    const MotionOptions& motion_options() const { return m_motion_options; }
    /// The keys as given: 12 floats per matrix key, 16 per SRT key.
    const std::vector<float>& motion_keys() const { return m_motion_keys; }
    unsigned motion_key_count() const;
    /// A user id that hit programs below read with instance_id() (default 0; OptiX's
    /// OptixInstance::instanceId). Of nested Transforms, the innermost's is read.
    void set_instance_id(unsigned id);
    unsigned instance_id() const { return m_instance_id; }

  private:
    std::shared_ptr<Node> m_child;
    Matrix4x3 m_matrix;
    unsigned m_instance_id = 0;
    TransformMotion m_motion = TransformMotion::kNone;
    MotionOptions m_motion_options;
    std::vector<float> m_motion_keys;
};

class Material;

/// What a geometry's primitives are: programs of the user's (Geometry), or built into
/// the engine's traversal with their own intersection code (OptiX's OptixPrimitiveType).
enum class PrimitiveType { kCustom, kTriangles, kSpheres, kCurves };

/// Common base of Geometry (custom primitives) and the built-in GeometryTriangles,
/// GeometrySpheres and GeometryCurves.
class GeometryBase : public ContextObject, public VariableScope {
  public:
    using ContextObject::ContextObject;
    virtual PrimitiveType primitive_type() const = 0;
    bool is_triangles() const { return primitive_type() == PrimitiveType::kTriangles; }
    virtual unsigned primitive_count() const = 0;
    std::string scope_name() const override { return describe(); }
    /// GeometryFlags, or'ed (default kGeometryFlagNone); kGeometryFlagDisableAnyHit makes the
    /// geometry opaque: its any-hit programs never run unless a ray has
    /// kRayFlagEnforceAnyHit. An unknown flag is an error.
    void set_flags(unsigned flags);
    unsigned flags() const { return m_flags; }
    /// Motion keys of a built-in primitive (GeometryTriangles' vertices, GeometrySpheres'
    /// centres): one buffer per key, empty when static.
    const std::vector<std::shared_ptr<Buffer>>& motion_buffers() const { return m_motion_buffers; }
    const MotionOptions& motion_options() const { return m_motion_options; }

  protected:
    void variables_changed() override { changed(); }
    /// Stores checked motion keys (two or more buffers, a valid time range).
    void set_motion_buffers(std::vector<std::shared_ptr<Buffer>> keys, const MotionOptions& options,
                            const char* what);
    void clear_motion_buffers() { m_motion_buffers.clear(); }

  private:
    unsigned m_flags = kGeometryFlagNone;
    std::vector<std::shared_ptr<Buffer>> m_motion_buffers;
    MotionOptions m_motion_options;
};

/// Custom primitives: a bounding-box and an intersection program shared by all of them.
class Geometry : public GeometryBase {
  public:
    using GeometryBase::GeometryBase;
    std::string describe() const override;
    PrimitiveType primitive_type() const override { return PrimitiveType::kCustom; }
    void set_primitive_count(unsigned count);
    unsigned primitive_count() const override { return m_count; }
    void set_bounding_box_program(std::shared_ptr<Program> program);
    void set_intersection_program(std::shared_ptr<Program> program);
    const std::shared_ptr<Program>& bounding_box_program() const { return m_bounds; }
    const std::shared_ptr<Program>& intersection_program() const { return m_intersect; }

  private:
    unsigned m_count = 0;
    std::shared_ptr<Program> m_bounds, m_intersect;
};

/// Built-in triangles: a float3 vertex buffer, an optional uint3 index buffer, an optional
/// unsigned per-triangle material index buffer, and an optional attribute program.
class GeometryTriangles : public GeometryBase {
  public:
    using GeometryBase::GeometryBase;
    std::string describe() const override;
    PrimitiveType primitive_type() const override { return PrimitiveType::kTriangles; }
    void set_vertices(std::shared_ptr<Buffer> vertices);
    void set_indices(std::shared_ptr<Buffer> indices);
    void set_material_indices(std::shared_ptr<Buffer> material_indices);
    void set_attribute_program(std::shared_ptr<Program> program);
    /// Motion triangles (OptiX's vertexBuffers with numKeys > 1): one float3 vertex buffer
    /// per key, each as long as the first, spaced evenly over `options`' time range; a ray
    /// meets the vertices interpolated linearly at its time. The first key becomes
    /// vertices(); set_vertices makes the geometry static again.
    void set_motion_vertices(std::vector<std::shared_ptr<Buffer>> keys,
                             const MotionOptions& options = {});
    const std::shared_ptr<Buffer>& vertices() const { return m_vertices; }
    const std::shared_ptr<Buffer>& indices() const { return m_indices; }
    const std::shared_ptr<Buffer>& material_indices() const { return m_material_indices; }
    const std::shared_ptr<Program>& attribute_program() const { return m_attributes; }
    unsigned primitive_count() const override;

  private:
    std::shared_ptr<Buffer> m_vertices, m_indices, m_material_indices;
    std::shared_ptr<Program> m_attributes;
};

/// Built-in spheres (OptiX's OPTIX_PRIMITIVE_TYPE_SPHERE): a float3 centre buffer, a float
/// radius buffer with one radius per sphere or one for all, and an optional unsigned
/// per-sphere material index buffer. Hit programs read BuiltinSphereAttributes (the
/// object-space normal); a ray reports both of a sphere's intersections, so one starting inside hits
/// its far side. Bounds come from the centres and radii: no programs to write.
class GeometrySpheres : public GeometryBase {
  public:
    using GeometryBase::GeometryBase;
    std::string describe() const override;
    PrimitiveType primitive_type() const override { return PrimitiveType::kSpheres; }
    void set_centers(std::shared_ptr<Buffer> centers);
    void set_radii(std::shared_ptr<Buffer> radii);
    void set_material_indices(std::shared_ptr<Buffer> material_indices);
    /// Moving spheres (OptiX's vertexBuffers with numKeys > 1): one float3 centre buffer per
    /// key, each as long as the first, spaced evenly over `options`' time range; a ray meets
    /// the centres interpolated linearly at its time (the radii stay those of set_radii).
    /// The first key becomes centers(); set_centers makes the spheres static again.
    void set_motion_centers(std::vector<std::shared_ptr<Buffer>> keys,
                            const MotionOptions& options = {});
    const std::shared_ptr<Buffer>& centers() const { return m_centers; }
    const std::shared_ptr<Buffer>& radii() const { return m_radii; }
    const std::shared_ptr<Buffer>& material_indices() const { return m_material_indices; }
    unsigned primitive_count() const override;

  private:
    std::shared_ptr<Buffer> m_centers, m_radii, m_material_indices;
};

/// Built-in curves (OptiX's OPTIX_PRIMITIVE_TYPE_ROUND_LINEAR, _QUADRATIC_BSPLINE,
/// _CUBIC_BSPLINE and _CATMULLROM): round tubes along a centre line with a radius per
/// control point. A float3 vertex buffer and a float radius buffer (one per vertex), and an
/// unsigned segment index buffer: segment i reads curve_control_points(type) consecutive
/// vertices from segment_indices[i] (2 for linear, 3 for quadratic, 4 for cubic and
/// Catmull-Rom); an optional unsigned per-segment material index buffer. Hit programs read
/// BuiltinCurveAttributes (normal, the segment's parameter u). Bounds come from the data.
class GeometryCurves : public GeometryBase {
  public:
    using GeometryBase::GeometryBase;
    std::string describe() const override;
    PrimitiveType primitive_type() const override { return PrimitiveType::kCurves; }
    void set_curve_type(CurveType type);
    CurveType curve_type() const { return m_type; }
    void set_vertices(std::shared_ptr<Buffer> vertices);
    void set_radii(std::shared_ptr<Buffer> radii);
    void set_segment_indices(std::shared_ptr<Buffer> segment_indices);
    void set_material_indices(std::shared_ptr<Buffer> material_indices);
    const std::shared_ptr<Buffer>& vertices() const { return m_vertices; }
    const std::shared_ptr<Buffer>& radii() const { return m_radii; }
    const std::shared_ptr<Buffer>& segment_indices() const { return m_segments; }
    const std::shared_ptr<Buffer>& material_indices() const { return m_material_indices; }
    unsigned primitive_count() const override;

  private:
    CurveType m_type = kCurveCubicBSpline;
    std::shared_ptr<Buffer> m_vertices, m_radii, m_segments, m_material_indices;
};

/// Closest-hit and any-hit programs per ray type.
class Material : public ContextObject, public VariableScope {
  public:
    using ContextObject::ContextObject;
    std::string describe() const override;
    std::string scope_name() const override { return describe(); }
    void set_closest_hit(unsigned ray_type, std::shared_ptr<Program> program);
    void set_any_hit(unsigned ray_type, std::shared_ptr<Program> program);
    /// The program for the ray type, or null.
    std::shared_ptr<Program> closest_hit(unsigned ray_type) const;
    std::shared_ptr<Program> any_hit(unsigned ray_type) const;
    /// One more than the highest ray type that has a program here.
    unsigned ray_type_slots() const { return unsigned(std::max(m_closest.size(), m_any.size())); }

  protected:
    void variables_changed() override { changed(); }

  private:
    std::vector<std::shared_ptr<Program>> m_closest, m_any;
};

/// Binds a geometry to its materials (material index reported by intersection selects).
class GeometryInstance : public ContextObject, public VariableScope {
  public:
    using ContextObject::ContextObject;
    std::string describe() const override;
    std::string scope_name() const override { return describe(); }
    void set_geometry(std::shared_ptr<GeometryBase> geometry);
    const std::shared_ptr<GeometryBase>& geometry() const { return m_geometry; }
    /// Appends a material; returns its index.
    unsigned add_material(std::shared_ptr<Material> material);
    void set_material(unsigned index, std::shared_ptr<Material> material);
    unsigned material_count() const { return unsigned(m_materials.size()); }
    const std::shared_ptr<Material>& material(unsigned index) const;
    /// The instance's 8-bit visibility mask (default 0xff): rays whose mask shares no bit
    /// with it skip its primitives. A mask above 0xff is an error.
    void set_visibility_mask(unsigned mask);
    unsigned visibility_mask() const { return m_visibility_mask; }
    /// A user id that hit programs read with geometry_instance_id() (default 0).
    void set_instance_id(unsigned id);
    unsigned instance_id() const { return m_instance_id; }

  protected:
    void variables_changed() override { changed(); }

  private:
    std::shared_ptr<GeometryBase> m_geometry;
    std::vector<std::shared_ptr<Material>> m_materials;
    unsigned m_visibility_mask = kVisibilityMaskAll;
    unsigned m_instance_id = 0;
};

/// Leaves of the graph: geometry instances under one acceleration structure.
class GeometryGroup : public Node {
  public:
    GeometryGroup(detail::OwnerRef owner, std::string name, std::shared_ptr<Acceleration> accel)
        : Node(std::move(owner), std::move(name), NodeKind::kGeometryGroup),
          m_accel(std::move(accel)) {}
    unsigned add_child(std::shared_ptr<GeometryInstance> instance);
    void set_child(unsigned index, std::shared_ptr<GeometryInstance> instance);
    void remove_child(unsigned index);
    unsigned child_count() const { return unsigned(m_children.size()); }
    const std::shared_ptr<GeometryInstance>& child(unsigned index) const;
    const std::vector<std::shared_ptr<GeometryInstance>>& children() const { return m_children; }
    const std::shared_ptr<Acceleration>& acceleration() const { return m_accel; }
    void set_acceleration(std::shared_ptr<Acceleration> accel);

  private:
    std::vector<std::shared_ptr<GeometryInstance>> m_children;
    std::shared_ptr<Acceleration> m_accel;
};

}  // namespace lucent

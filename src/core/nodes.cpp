// Scene-graph node objects: setters check their arguments and mark the scene stale.
#include "lucent/nodes.h"

#include <cmath>
#include <cstdio>

namespace lucent {

const char* node_kind_name(NodeKind kind) {
    switch (kind) {
        case NodeKind::kGroup:
            return "Group";
        case NodeKind::kGeometryGroup:
            return "GeometryGroup";
        case NodeKind::kTransform:
            return "Transform";
        case NodeKind::kSelector:
            return "Selector";
    }
    return "?";
}

namespace {
std::string hex(unsigned value) {
    char text[16];
    std::snprintf(text, sizeof text, "%x", value);
    return text;
}
template <class T>
void require(const std::shared_ptr<T>& p, const ContextObject& owner, const char* what) {
    if (!p)
        throw Error(owner.describe() + ": " + what +
                    " is null; pass an object created by the Context");
}
template <class T>
void require_same_context(const std::shared_ptr<T>& p, const ContextObject& owner) {
    if (p && p->owner() != owner.owner())
        throw Error(owner.describe() + ": " + p->describe() +
                    " belongs to another Context; create it with this node's Context");
}
/// `buffer` is a 1D buffer of `element`; else Error "<owner>: <what> must be a 1D buffer of
/// <type>, got ...".
void require_1d_buffer_of(const Buffer& buffer, const TypeInfo& element, const ContextObject& owner,
                          const char* what, const char* type) {
    if (!same_type(buffer.element(), element) || buffer.dimensionality() != 1)
        throw Error(owner.describe() + ": " + what + " must be a 1D buffer of " + type +
                    ", got " + buffer.describe());
}
void require_visibility_mask(const ContextObject& owner, unsigned mask) {
    if (mask > kVisibilityMaskAll)
        throw Error(owner.describe() + ": visibility mask 0x" + hex(mask) +
                    " has more than 8 bits; pass a mask in 0x00..0xff");
}
/// Error unless `options` is a usable motion time range.
void require_motion_options(const ContextObject& owner, const MotionOptions& options) {
    if (!std::isfinite(options.time_begin) || !std::isfinite(options.time_end) ||
        !(options.time_begin < options.time_end))
        throw Error(owner.describe() + ": the motion time range [" +
                    std::to_string(options.time_begin) + ", " + std::to_string(options.time_end) +
                    "] is not valid; give finite times with time_begin < time_end");
    if (options.flags & ~unsigned(kMotionFlagStartVanish | kMotionFlagEndVanish))
        throw Error(owner.describe() + ": motion flags 0x" + hex(options.flags) +
                    " include an unknown flag; the flags are kMotionFlagNone, "
                    "kMotionFlagStartVanish and kMotionFlagEndVanish");
}
void require_motion_key_count(const ContextObject& owner, size_t count) {
    if (count < 2)
        throw Error(owner.describe() + ": motion needs at least 2 keys, got " +
                    std::to_string(count) + "; for a static object set it without motion");
}
std::string index_error(const ContextObject& owner, const char* what, unsigned index,
                        size_t count) {
    return owner.describe() + ": " + what + " index " + std::to_string(index) +
           " is out of range; it has " + std::to_string(count) + " (valid: 0.." +
           (count ? std::to_string(count - 1) : std::string("none")) + ")";
}
}  // namespace

std::string Acceleration::describe() const {
    return "Acceleration '" + name() + "'";
}
void Acceleration::set_builder(Builder builder) {
    m_builder = builder;
    mark_dirty();
}
void Acceleration::set_refit(bool refit) {
    m_refit = refit;
    changed();
}
void Acceleration::mark_dirty() {
    m_dirty = true;
    changed();
}

std::string Node::describe() const {
    return std::string(node_kind_name(m_kind)) + " '" + name() + "'";
}
void Node::set_visibility_mask(unsigned mask) {
    require_visibility_mask(*this, mask);
    m_visibility_mask = mask;
    changed();
}

unsigned NodeWithChildren::add_child(std::shared_ptr<Node> child) {
    require(child, *this, "child");
    require_same_context(child, *this);
    m_children.push_back(std::move(child));
    children_changed();
    return unsigned(m_children.size() - 1);
}
void NodeWithChildren::set_child(unsigned index, std::shared_ptr<Node> child) {
    require(child, *this, "child");
    require_same_context(child, *this);
    if (index >= m_children.size())
        throw Error(index_error(*this, "child", index, m_children.size()));
    m_children[index] = std::move(child);
    children_changed();
}
void NodeWithChildren::remove_child(unsigned index) {
    if (index >= m_children.size())
        throw Error(index_error(*this, "child", index, m_children.size()));
    m_children.erase(m_children.begin() + index);
    children_changed();
}
const std::shared_ptr<Node>& NodeWithChildren::child(unsigned index) const {
    if (index >= m_children.size())
        throw Error(index_error(*this, "child", index, m_children.size()));
    return m_children[index];
}

void Group::set_acceleration(std::shared_ptr<Acceleration> accel) {
    require(accel, *this, "acceleration");
    m_accel = std::move(accel);
    m_accel->mark_dirty();
}
void Group::children_changed() {
    m_accel->mark_dirty();
    changed();
}

void Selector::set_visit_program(std::shared_ptr<Program> visit) {
    require(visit, *this, "visit program");
    if (visit->kind() != ProgramKind::kVisit)
        throw Error(describe() + ": " + visit->describe() +
                    " is not a selector visit program; define it with LUCENT_VISIT");
    m_visit = std::move(visit);
    changed();
}

Transform::Transform(detail::OwnerRef owner, std::string name)
    : Node(std::move(owner), std::move(name), NodeKind::kTransform),
      m_matrix{{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}} {}
void Transform::set_child(std::shared_ptr<Node> child) {
    require(child, *this, "child");
    require_same_context(child, *this);
    m_child = std::move(child);
    changed();
}
void Transform::set_motion_matrices(std::span<const Matrix4x3> keys, const MotionOptions& options) {
    require_motion_key_count(*this, keys.size());
    require_motion_options(*this, options);
    std::vector<float> flat;
    for (size_t k = 0; k < keys.size(); ++k)
        for (float v : keys[k].m) {
            if (!std::isfinite(v))
                throw Error(describe() + ": motion key " + std::to_string(k) +
                            " has a non-finite entry (NaN or infinity); give finite matrices");
            flat.push_back(v);
        }
    m_motion = TransformMotion::kMatrix;
    m_motion_options = options;
    m_motion_keys = std::move(flat);
    m_matrix = keys[0];
    changed();
}
void Transform::set_motion_srt(std::span<const SrtData> keys, const MotionOptions& options) {
    require_motion_key_count(*this, keys.size());
    require_motion_options(*this, options);
    std::vector<float> flat;
    for (size_t k = 0; k < keys.size(); ++k) {
        const SrtData& d = keys[k];
        const float v[16] = {d.sx,  d.a,  d.b,  d.pvx, d.sy, d.c,  d.pvy, d.sz,
                             d.pvz, d.qx, d.qy, d.qz,  d.qw, d.tx, d.ty,  d.tz};
        for (float x : v)
            if (!std::isfinite(x))
                throw Error(describe() + ": SRT key " + std::to_string(k) +
                            " has a non-finite component (NaN or infinity); give finite keys");
        if (!(d.qx * d.qx + d.qy * d.qy + d.qz * d.qz + d.qw * d.qw > 0.0f))
            throw Error(describe() + ": SRT key " + std::to_string(k) +
                        " has a zero quaternion; give a unit quaternion (qw = 1 for none)");
        flat.insert(flat.end(), v, v + 16);
    }
    m_motion = TransformMotion::kSrt;
    m_motion_options = options;
    m_motion_keys = std::move(flat);
    changed();
}
unsigned Transform::motion_key_count() const {
    switch (m_motion) {
        case TransformMotion::kMatrix:
            return unsigned(m_motion_keys.size() / 12);
        case TransformMotion::kSrt:
            return unsigned(m_motion_keys.size() / 16);
        default:
            return 0;
    }
}
void Transform::set_matrix(const float m[12], bool transpose) {
    m_motion = TransformMotion::kNone;
    m_motion_keys.clear();
    // Non-finite or singular matrices are reported at validate/launch, where the message
    // can say which node in the graph it is; here we only store.
    if (!transpose) {
        for (int i = 0; i < 12; ++i) m_matrix.m[i] = m[i];
    } else {  // column-major 4x3 input: m[c*3 + r]
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) m_matrix.m[r * 4 + c] = m[c * 3 + r];
    }
    changed();
}

void Transform::set_instance_id(unsigned id) {
    m_instance_id = id;
    changed();
}

void GeometryBase::set_flags(unsigned flags) {
    if (flags & ~unsigned(kGeometryFlagDisableAnyHit))
        throw Error(describe() + ": geometry flags 0x" + hex(flags) +
                    " include an unknown flag; the flags are kGeometryFlagNone and "
                    "kGeometryFlagDisableAnyHit");
    m_flags = flags;
    changed();
}

void GeometryBase::set_motion_buffers(std::vector<std::shared_ptr<Buffer>> keys,
                                      const MotionOptions& options, const char* what) {
    require_motion_key_count(*this, keys.size());
    require_motion_options(*this, options);
    for (size_t k = 0; k < keys.size(); ++k) {
        const std::string label = std::string(what) + " of motion key " + std::to_string(k);
        require(keys[k], *this, label.c_str());
        require_same_context(keys[k], *this);
        require_1d_buffer_of(*keys[k], type_info_of<float3>(), *this, label.c_str(), "float3");
        if (keys[k]->count() != keys[0]->count())
            throw Error(describe() + ": motion key " + std::to_string(k) + " has " +
                        std::to_string(keys[k]->count()) + " " + what + " but key 0 has " +
                        std::to_string(keys[0]->count()) + "; give every key the same count");
    }
    m_motion_buffers = std::move(keys);
    m_motion_options = options;
}

std::string Geometry::describe() const {
    return "Geometry '" + name() + "'";
}
void Geometry::set_primitive_count(unsigned count) {
    m_count = count;
    changed();
}
void Geometry::set_bounding_box_program(std::shared_ptr<Program> program) {
    require(program, *this, "bounding-box program");
    if (program->kind() != ProgramKind::kBoundingBox)
        throw Error(describe() + ": " + program->describe() +
                    " is not a bounding-box program; define it with LUCENT_BOUNDING_BOX");
    m_bounds = std::move(program);
    changed();
}
void Geometry::set_intersection_program(std::shared_ptr<Program> program) {
    require(program, *this, "intersection program");
    if (program->kind() != ProgramKind::kIntersection)
        throw Error(describe() + ": " + program->describe() +
                    " is not an intersection program; define it with LUCENT_INTERSECTION");
    m_intersect = std::move(program);
    changed();
}

std::string GeometryTriangles::describe() const {
    return "GeometryTriangles '" + name() + "'";
}
void GeometryTriangles::set_vertices(std::shared_ptr<Buffer> vertices) {
    require(vertices, *this, "vertex buffer");
    require_1d_buffer_of(*vertices, type_info_of<float3>(), *this, "vertices", "float3");
    m_vertices = std::move(vertices);
    clear_motion_buffers();
    changed();
}
void GeometryTriangles::set_motion_vertices(std::vector<std::shared_ptr<Buffer>> keys,
                                            const MotionOptions& options) {
    set_motion_buffers(std::move(keys), options, "vertices");
    m_vertices = motion_buffers()[0];
    changed();
}
void GeometryTriangles::set_indices(std::shared_ptr<Buffer> indices) {
    if (indices &&
        (indices->dimensionality() != 1 || (!same_type(indices->element(), type_info_of<uint3>()) &&
                                            !same_type(indices->element(), type_info_of<int3>()))))
        throw Error(describe() + ": indices must be a 1D buffer of uint3 or int3, got " +
                    indices->describe());
    m_indices = std::move(indices);
    changed();
}
void GeometryTriangles::set_material_indices(std::shared_ptr<Buffer> material_indices) {
    if (material_indices)
        require_1d_buffer_of(*material_indices, type_info_of<unsigned>(), *this,
                             "material indices", "unsigned");
    m_material_indices = std::move(material_indices);
    changed();
}
void GeometryTriangles::set_attribute_program(std::shared_ptr<Program> program) {
    if (program && program->kind() != ProgramKind::kAttribute)
        throw Error(describe() + ": " + program->describe() +
                    " is not an attribute program; define it with LUCENT_ATTRIBUTE");
    m_attributes = std::move(program);
    changed();
}
unsigned GeometryTriangles::primitive_count() const {
    if (m_indices) return unsigned(m_indices->count());
    return m_vertices ? unsigned(m_vertices->count() / 3) : 0;
}

std::string GeometrySpheres::describe() const {
    return "GeometrySpheres '" + name() + "'";
}
void GeometrySpheres::set_centers(std::shared_ptr<Buffer> centers) {
    require(centers, *this, "centre buffer");
    require_1d_buffer_of(*centers, type_info_of<float3>(), *this, "centres", "float3");
    m_centers = std::move(centers);
    clear_motion_buffers();
    changed();
}
void GeometrySpheres::set_motion_centers(std::vector<std::shared_ptr<Buffer>> keys,
                                         const MotionOptions& options) {
    set_motion_buffers(std::move(keys), options, "centres");
    m_centers = motion_buffers()[0];
    changed();
}
void GeometrySpheres::set_radii(std::shared_ptr<Buffer> radii) {
    require(radii, *this, "radius buffer");
    require_1d_buffer_of(*radii, type_info_of<float>(), *this, "radii", "float");
    m_radii = std::move(radii);
    changed();
}
void GeometrySpheres::set_material_indices(std::shared_ptr<Buffer> material_indices) {
    if (material_indices)
        require_1d_buffer_of(*material_indices, type_info_of<unsigned>(), *this,
                             "material indices", "unsigned");
    m_material_indices = std::move(material_indices);
    changed();
}
unsigned GeometrySpheres::primitive_count() const {
    return m_centers ? unsigned(m_centers->count()) : 0;
}

std::string GeometryCurves::describe() const {
    return "GeometryCurves '" + name() + "'";
}
void GeometryCurves::set_curve_type(CurveType type) {
    if (unsigned(type) >= kCurveTypeCount)
        throw Error(describe() + ": curve type " + std::to_string(unsigned(type)) +
                    " is not one of kCurveLinear, kCurveQuadraticBSpline, kCurveCubicBSpline "
                    "and kCurveCatmullRom");
    m_type = type;
    changed();
}
void GeometryCurves::set_vertices(std::shared_ptr<Buffer> vertices) {
    require(vertices, *this, "vertex buffer");
    require_1d_buffer_of(*vertices, type_info_of<float3>(), *this, "vertices", "float3");
    m_vertices = std::move(vertices);
    changed();
}
void GeometryCurves::set_radii(std::shared_ptr<Buffer> radii) {
    require(radii, *this, "radius buffer");
    require_1d_buffer_of(*radii, type_info_of<float>(), *this, "radii", "float");
    m_radii = std::move(radii);
    changed();
}
void GeometryCurves::set_segment_indices(std::shared_ptr<Buffer> segment_indices) {
    require(segment_indices, *this, "segment index buffer");
    require_1d_buffer_of(*segment_indices, type_info_of<unsigned>(), *this, "segment indices",
                         "unsigned");
    m_segments = std::move(segment_indices);
    changed();
}
void GeometryCurves::set_material_indices(std::shared_ptr<Buffer> material_indices) {
    if (material_indices)
        require_1d_buffer_of(*material_indices, type_info_of<unsigned>(), *this,
                             "material indices", "unsigned");
    m_material_indices = std::move(material_indices);
    changed();
}
unsigned GeometryCurves::primitive_count() const {
    return m_segments ? unsigned(m_segments->count()) : 0;
}

std::string Material::describe() const {
    return "Material '" + name() + "'";
}
void Material::set_closest_hit(unsigned ray_type, std::shared_ptr<Program> program) {
    if (program && program->kind() != ProgramKind::kClosestHit)
        throw Error(describe() + ": " + program->describe() +
                    " is not a closest-hit program; define it with LUCENT_CLOSEST_HIT");
    if (ray_type >= 64)
        throw Error(describe() + ": ray type " + std::to_string(ray_type) +
                    " is out of range; declare ray types 0, 1, ... with Context::set_ray_type");
    if (m_closest.size() <= ray_type) m_closest.resize(ray_type + 1);
    m_closest[ray_type] = std::move(program);
    changed();
}
void Material::set_any_hit(unsigned ray_type, std::shared_ptr<Program> program) {
    if (program && program->kind() != ProgramKind::kAnyHit)
        throw Error(describe() + ": " + program->describe() +
                    " is not an any-hit program; define it with LUCENT_ANY_HIT");
    if (ray_type >= 64)
        throw Error(describe() + ": ray type " + std::to_string(ray_type) +
                    " is out of range; declare ray types 0, 1, ... with Context::set_ray_type");
    if (m_any.size() <= ray_type) m_any.resize(ray_type + 1);
    m_any[ray_type] = std::move(program);
    changed();
}
std::shared_ptr<Program> Material::closest_hit(unsigned ray_type) const {
    return ray_type < m_closest.size() ? m_closest[ray_type] : nullptr;
}
std::shared_ptr<Program> Material::any_hit(unsigned ray_type) const {
    return ray_type < m_any.size() ? m_any[ray_type] : nullptr;
}

std::string GeometryInstance::describe() const {
    return "GeometryInstance '" + name() + "'";
}
void GeometryInstance::set_geometry(std::shared_ptr<GeometryBase> geometry) {
    require(geometry, *this, "geometry");
    require_same_context(geometry, *this);
    m_geometry = std::move(geometry);
    changed();
}
unsigned GeometryInstance::add_material(std::shared_ptr<Material> material) {
    require(material, *this, "material");
    require_same_context(material, *this);
    m_materials.push_back(std::move(material));
    changed();
    return unsigned(m_materials.size() - 1);
}
void GeometryInstance::set_material(unsigned index, std::shared_ptr<Material> material) {
    require(material, *this, "material");
    require_same_context(material, *this);
    if (index >= m_materials.size()) m_materials.resize(index + 1);
    m_materials[index] = std::move(material);
    changed();
}
const std::shared_ptr<Material>& GeometryInstance::material(unsigned index) const {
    if (index >= m_materials.size())
        throw Error(index_error(*this, "material", index, m_materials.size()));
    return m_materials[index];
}

void GeometryInstance::set_visibility_mask(unsigned mask) {
    require_visibility_mask(*this, mask);
    m_visibility_mask = mask;
    changed();
}
void GeometryInstance::set_instance_id(unsigned id) {
    m_instance_id = id;
    changed();
}

unsigned GeometryGroup::add_child(std::shared_ptr<GeometryInstance> instance) {
    require(instance, *this, "child");
    require_same_context(instance, *this);
    m_children.push_back(std::move(instance));
    m_accel->mark_dirty();
    return unsigned(m_children.size() - 1);
}
void GeometryGroup::set_child(unsigned index, std::shared_ptr<GeometryInstance> instance) {
    require(instance, *this, "child");
    require_same_context(instance, *this);
    if (index >= m_children.size())
        throw Error(index_error(*this, "child", index, m_children.size()));
    m_children[index] = std::move(instance);
    m_accel->mark_dirty();
}
void GeometryGroup::remove_child(unsigned index) {
    if (index >= m_children.size())
        throw Error(index_error(*this, "child", index, m_children.size()));
    m_children.erase(m_children.begin() + index);
    m_accel->mark_dirty();
}
const std::shared_ptr<GeometryInstance>& GeometryGroup::child(unsigned index) const {
    if (index >= m_children.size())
        throw Error(index_error(*this, "child", index, m_children.size()));
    return m_children[index];
}
void GeometryGroup::set_acceleration(std::shared_ptr<Acceleration> accel) {
    require(accel, *this, "acceleration");
    m_accel = std::move(accel);
    m_accel->mark_dirty();
}

}  // namespace lucent

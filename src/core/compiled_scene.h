// The compiled scene: what a backend launches. Built from the node graph by
// SceneCompiler (validation, variable resolution, record packing, acceleration builds).
// Everything here is flat arrays indexed by integers, so the CUDA backend can upload it.
#pragma once

#include <map>
#include <memory>
#include <vector>

#include "accel/bvh.h"
#include "accel/triangle_accel.h"
#include "lucent/context.h"
#include "lucent/device/curve_intersect.h"
#include "lucent/device/program.h"
#include "lucent/module.h"
#include "runtime/motion.h"

namespace lucent::core {

/// A program's record, resolved and packed (16-byte aligned storage).
class PackedRecord {
  public:
    void resize(size_t bytes) { m_blocks.assign((bytes + 15) / 16, Block{}); }
    unsigned char* data() { return m_blocks.empty() ? nullptr : m_blocks[0].bytes; }
    const unsigned char* data() const { return m_blocks.empty() ? nullptr : m_blocks[0].bytes; }
    size_t size() const { return m_blocks.size() * 16; }

  private:
    struct alignas(16) Block {
        unsigned char bytes[16];
    };
    std::vector<Block> m_blocks;
};

/// A bound program: its description and its packed record.
struct CompiledProgram {
    const ProgramDesc* desc = nullptr;
    std::shared_ptr<PackedRecord> record;  // shared: callables point into it
    std::string label;                     // "closest hit 'phong' of Material 'glass'"
    std::vector<std::shared_ptr<const Buffer>>
        buffers;  // every buffer the record views (kept alive)
    /// Those viewed through a BufferView<T> that is not BufferView<const T>.
    std::vector<std::shared_ptr<const Buffer>> writable_buffers;

    explicit operator bool() const { return desc != nullptr; }
    const void* rec() const { return record ? record->data() : nullptr; }
    template <class Fn>
    Fn entry() const {
        return reinterpret_cast<Fn>(desc->entry);
    }
};

struct CompiledMaterial {
    std::vector<CompiledProgram> closest_hit;  // per ray type
    std::vector<CompiledProgram> any_hit;      // per ray type
};

/// A GeometryInstance with its records resolved (GeometryInstance scope included).
struct CompiledInstance {
    const GeometryInstance* source = nullptr;
    PrimitiveType type = PrimitiveType::kCustom;
    unsigned primitive_count = 0;
    CompiledProgram intersection, bounding_box, attribute;
    std::vector<CompiledMaterial> materials;
    const TypeInfo* attributes = nullptr;  // the attribute type this geometry produces
    bool opaque = false;                   // kGeometryFlagDisableAnyHit
    unsigned visibility_mask = kVisibilityMaskAll;
    unsigned user_id = 0;  // GeometryInstance::set_instance_id
    // Built-in triangles (host pointers into the Buffers).
    const float3* vertices = nullptr;
    const uint3* indices = nullptr;  // null: triangle i is vertices 3i..3i+2
    const unsigned* material_indices = nullptr;  // triangles and spheres
    // Built-in spheres.
    const float3* centers = nullptr;
    const float* radii = nullptr;
    bool single_radius = false;  // radii[0] for every sphere
    float radius(unsigned prim) const { return radii[single_radius ? 0 : prim]; }
    // Built-in curves: vertices and radii (one per vertex) above, and each segment's first
    // control point.
    const unsigned* segments = nullptr;
    CurveType curve_type = kCurveCubicBSpline;
    /// Motion keys (kMotionVertices: triangles' vertices or spheres' centres per key, in
    /// CompiledScene::motion), or kMotionNone; `motion_points` per key.
    runtime::MotionRange motion{};
    unsigned motion_points = 0;
    bool triangles() const { return type == PrimitiveType::kTriangles; }
    /// Built-in triangles: the vertex indices of triangle `prim`.
    uint3 triangle(unsigned prim) const {
        return indices ? indices[prim] : uint3{3 * prim, 3 * prim + 1, 3 * prim + 2};
    }
    /// Built-in triangles: their geometry (null for other primitives).
    const GeometryTriangles* triangle_geometry() const {
        return triangles() ? static_cast<const GeometryTriangles*>(source->geometry().get())
                           : nullptr;
    }
    /// The primitives of the group's BVH this instance adds: one per primitive, but
    /// curve_references(type) per curve segment, each boxing part of it.
    unsigned bvh_references() const {
        return type == PrimitiveType::kCurves ? primitive_count * curve_references(curve_type)
                                              : primitive_count;
    }
};

/// Acceleration data of a GeometryGroup, kept across compiles while unchanged.
struct GeometryAccel {
    uint64_t structure_signature = 0;  // instances, primitive counts, index buffers
    uint64_t content_signature = 0;    // vertex buffer versions, bounding-box records
    bool triangles_only = false;
    accel::TriangleAccel triangles;      // triangles_only: all instances' triangles together
    bool host_triangles = false;         // `triangles` is built (kGpuHploc on a GPU needs none)
    unsigned triangle_count = 0;         // triangles_only: of every instance together
    // host_triangles: the instances' triangles gathered (core/triangle_gather.h); without a
    // host build they are left empty, and a GPU build gathers them on the device.
    std::vector<float3> vertices;        // the concatenated vertices
    std::vector<uint3> indices;          // concatenated, rebased indices
    std::vector<uint32_t> tri_instance;  // triangle → position in CompiledNode::instances
    accel::Bvh bvh;                      // otherwise: over every primitive of every instance
    std::vector<uint32_t> prim_first;    // per instance: first global primitive (and triangle)
    Aabb bounds{};
};

struct CompiledNode {
    NodeKind kind = NodeKind::kGroup;
    const Node* source = nullptr;
    std::vector<unsigned> children;           // node indices (Transform: one)
    std::vector<unsigned> instances;          // GeometryGroup: CompiledInstance indices
    std::shared_ptr<GeometryAccel> geometry;  // GeometryGroup
    accel::Bvh child_bvh;                     // Group: over children's boxes
    bool brute_force = false;                 // Builder::kNone
    Matrix4x3 to_world{}, to_object{};        // Transform (a motion Transform: its first key)
    runtime::MotionRange motion{};            // Transform: its keys, or kMotionNone
    CompiledProgram visit;                    // Selector
    Aabb bounds{};
    unsigned visibility_mask = kVisibilityMaskAll;
    unsigned instance_id = 0;  // Transform: its user id (instance_id())
    // GeometryGroup: some material of a non-opaque instance has an any-hit for the ray type;
    // and of any instance, for rays with kRayFlagEnforceAnyHit.
    std::vector<bool> any_hit_for_ray_type;
    std::vector<bool> any_hit_enforced_for_ray_type;
    bool instances_masked = false;  // GeometryGroup: an instance's mask is not 0xff
};

struct CompiledEntry {
    CompiledProgram ray_generation;
    CompiledProgram exception;
    std::vector<const Buffer*> output_buffers;  // Output buffers the ray-generation record views
    /// Every buffer a launch of this entry may write (any program it can run views it
    /// writably): Context::launch marks them written (Buffer::zeroed).
    std::vector<const Buffer*> written_buffers;
};

/// Whether `code` is among the enabled ones (kAllExceptions enables every code, and
/// kUserExceptionBase every user code).
inline bool exception_code_enabled(const std::vector<int>& enabled, int code) {
    for (int c : enabled)
        if (c == kAllExceptions || c == code || (code >= kUserExceptionBase && c == kUserExceptionBase))
            return true;
    return false;
}

struct CompiledScene {
    uint64_t generation = 0;
    uint64_t data_generation = 0;  // of the buffer contents this scene was checked against
    /// Buffers whose contents the compile built something from (acceleration structures'
    /// vertices, indices and bounding-box records; textures' texels), with their versions
    /// then: new contents in one of them need a recompile, in any other only an upload.
    std::vector<std::pair<const Buffer*, uint64_t>> rebuild_inputs;
    std::vector<CompiledEntry> entries;
    std::vector<RayTypeDesc> ray_types;
    std::vector<CompiledProgram> miss;  // per ray type
    std::vector<CompiledNode> nodes;
    std::vector<CompiledInstance> instances;
    /// Every motion key of the scene's Transforms and built-in primitives, as floats
    /// (runtime::MotionRange::offset points in here).
    std::vector<float> motion;
    bool has_motion() const { return !motion.empty(); }
    std::vector<CompiledProgram> callables;  // bound through variables; their records are the
                                             // targets of Callable::record
    unsigned max_depth = 8;
    bool print_enabled = false;
    int3 print_index{-1, -1, -1};
    std::vector<int> enabled_exceptions;  // codes whose exception program runs
    /// Some bound program's module declares kUsesOccluded: occluded() may be called (the
    /// GPU's megakernel has its occlusion path only then, and the CPU refuses it otherwise).
    bool uses_occluded = false;
    /// Some bound program's module declares kUsesRayFlags: trace() and occluded() may get
    /// ray flags and visibility masks.
    bool uses_ray_flags = false;
    /// Per-ray control is needed: modules pass ray flags, or some node or instance has a
    /// visibility mask, an instance id or opaque geometry (the GPU's LUCENT_GPU_RAY_CONTROL).
    bool needs_ray_control() const {
        if (uses_ray_flags) return true;
        for (const CompiledNode& n : nodes)
            if (n.visibility_mask != kVisibilityMaskAll || n.instance_id != 0) return true;
        for (const CompiledInstance& i : instances)
            if (i.visibility_mask != kVisibilityMaskAll || i.user_id != 0 || i.opaque) return true;
        return false;
    }
    /// Module texts given to the Context at run time (the GPU backend's JIT reads them
    /// before the texts embedded in the binary).
    std::map<const ModuleInfo*, std::shared_ptr<const ModuleSource>> module_sources;
    bool exception_enabled(int code) const { return exception_code_enabled(enabled_exceptions, code); }
};

}  // namespace lucent::core

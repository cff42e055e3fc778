// The compiled scene in device memory: flat arrays, records with device pointers, and a
// mirror of every Buffer the programs use. Uploads only what changed since the last launch.
#pragma once

#include <future>
#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include "core/compiled_scene.h"
#include "cuda/accel/gpu_bvh_builder.h"
#include "cuda/accel/gpu_triangle_bvh.h"
#include "cuda/backend/device_buffer.h"
#include "cuda/backend/tree_upgrader.h"
#include "cuda/jit/megakernel_generator.h"
#include "lucent_gpu/launch_params.cuh"

namespace lucent::cuda {

class GpuScene {
  public:
    /// For the device of `context` (current on the calling thread), of compute capability
    /// `sm` (x10). `builder`, if valid, is the GPU BVH builder being made on another thread
    /// (the first GPU build takes it; otherwise that build makes one). `upgrades`: what
    /// becomes of Builder::kAuto's GPU-built triangle trees (ContextOptions::tree_upgrades).
    GpuScene(int sm, CUcontext context, TreeUpgrades upgrades,
             std::future<std::unique_ptr<GpuBvhBuilder>> builder = {})
        : m_sm(sm),
          m_context(context),
          m_upgrades(upgrades),
          m_builder_on_the_way(std::move(builder)) {}

    /// Brings the device copy up to date with `scene` (a new compile) and re-uploads
    /// buffers whose host contents changed.
    void update(const core::CompiledScene& scene);
    /// Time the last update() spent building or refitting GPU triangle layouts, in ms.
    double accel_ms() const { return m_accel_ms; }
    /// Trees the last update() upgraded itself (TreeUpgrades::kWithBuild).
    unsigned trees_upgraded_in_update() const { return m_upgraded_in_update; }
    /// Puts the upgraded trees built since the last call (TreeUpgrades::kBackground) in place
    /// of the GPU-built ones, in device memory; returns how many. The flat arrays still point
    /// at the old trees: update() must run again before a launch when this returns more than 0.
    unsigned adopt_tree_upgrades();
    /// Uploads buffers changed by the host since the last launch (same compile).
    void sync_buffers();
    /// After a launch: buffers programs may write (output, input-output) are newer on the
    /// device; their host copies are fetched when the host reads them (fetch()).
    void mark_outputs_device_newer();
    /// Copies one buffer's device contents to its host copy (no-op if not mirrored).
    void fetch(const Buffer& buffer);
    /// The buffers whose device copy a launch wrote and the host has not fetched yet.
    std::vector<std::shared_ptr<const Buffer>> device_newer_buffers() const;
    /// The device copy of a buffer this compile uses, or 0.
    CUdeviceptr mirror(const Buffer& buffer) const;
    /// The device copy when it holds the buffer's newest contents (a launch wrote it, or
    /// the host has not changed it since the upload), else 0.
    CUdeviceptr current_mirror(const Buffer& buffer) const;

    /// The scene part of the launch parameters (per-launch fields left for the caller).
    const gpu::LaunchParams& params() const { return m_params; }
    const ProgramTable& programs() const { return m_programs; }
    gpu::ProgramRef ray_generation(unsigned entry) const { return m_entries[entry].first; }
    gpu::ProgramRef exception(unsigned entry) const { return m_entries[entry].second; }

  private:
    struct BufferMirror {
        DeviceBuffer memory;
        uint64_t version = 0;
        std::shared_ptr<const Buffer> buffer;  // alive while mirrored
        bool device_newer = false;
    };
    struct GeometryMirror {
        uint64_t structure = 0, content = 0;
        GpuTriangleBvhDevice bvh;  // the triangles in the GPU layout (Aila and Laine 2009)
        bool empty = true;
        uint64_t version = 0;          // of bvh: a number no other build or refit of any group had
        bool upgrade_pending = false;  // an upgrade of this version is queued or building
        // Its triangles changed while an upgrade was building (they move every frame, most
        // likely), or an upgrade failed: it keeps its GPU-built trees from then on.
        bool upgrades_off = false;
    };

    struct FlatScene;
    // update(), one step each, in this order.
    void add_programs(const core::CompiledScene& scene, FlatScene& flat);
    void flatten_instances(const core::CompiledScene& scene, FlatScene& flat);
    void flatten_nodes(const core::CompiledScene& scene, FlatScene& flat);
    gpu::GpuGeometryAccel flatten_geometry_accel(const core::CompiledScene& scene,
                                                 const core::CompiledNode& node,
                                                 FlatScene& flat);
    void upload(const core::CompiledScene& scene, const FlatScene& flat);
    void set_params(const core::CompiledScene& scene);
    void drop_unused(const FlatScene& flat);

    CUdeviceptr device_pointer(const std::shared_ptr<const Buffer>& buffer);
    gpu::ProgramRef add_program(const core::CompiledProgram& program);
    unsigned reserve_record(const core::CompiledProgram& program);
    void write_record(unsigned offset, const core::CompiledProgram& program);
    void fetch_mirror(BufferMirror& mirror);
    void patch_record(unsigned char* bytes, const core::CompiledProgram& program);
    void update_triangle_bvh(const core::CompiledScene& scene, const core::CompiledNode& node,
                             const std::optional<std::vector<DeviceTriangles>>& on_device,
                             GeometryMirror& mirror);
    void start_upgrade(const core::CompiledNode& node, GeometryMirror& mirror);
    std::optional<std::vector<DeviceTriangles>> mirrored_triangles(
        const core::CompiledScene& scene, const core::CompiledNode& node);

    int m_sm;
    CUcontext m_context;
    TreeUpgrades m_upgrades;
    std::unique_ptr<TreeUpgrader> m_upgrader;  // made by the first upgrade
    uint64_t m_last_version = 0;               // of the GeometryMirror trees
    unsigned m_upgraded_in_update = 0;
    double m_accel_ms = 0;
    struct {
        unsigned count = 0, cleared = 0;
        double bytes = 0, ms = 0;
    } m_mirror_uploads;  // the last update()'s buffer uploads (LUCENT_GPU_ACCEL_TIMES)
    std::unique_ptr<GpuBvhBuilder> m_bvh_builder;  // made when a GPU build (Builder::kAuto, kGpuHploc) needs it
    std::future<std::unique_ptr<GpuBvhBuilder>> m_builder_on_the_way;
    ProgramTable m_programs;
    std::vector<unsigned char> m_records;
    std::unordered_map<const void*, gpu::ProgramRef> m_callable_slots;  // by host record
    std::vector<std::pair<gpu::ProgramRef, gpu::ProgramRef>> m_entries;
    std::unordered_map<const Buffer*, BufferMirror> m_buffers, m_previous_buffers;
    std::unordered_map<const core::GeometryAccel*, GeometryMirror> m_geometry;
    gpu::LaunchParams m_params{};
    // Device copies of the flat arrays.
    DeviceBuffer m_nodes, m_children, m_bvh_nodes, m_prim_order, m_prim_refs, m_bvhs, m_accels,
        m_accel_instances, m_accel_prim_first, m_instances, m_materials, m_record_blob, m_miss,
        m_payload_signatures, m_motion;
};

}  // namespace lucent::cuda

// Generates the CUDA source of one megakernel for a compiled scene (OptiX paper §4-5):
// the engine's runtime and traversal, the program modules actually
// bound, and switch statements that dispatch to them, specialised on what the scene uses.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/compiled_scene.h"

namespace lucent::cuda {

/// Dispatch ids of the bound programs, one numbering per program kind.
class ProgramTable {
  public:
    /// The program's id in its kind's switch (assigned on first sight); -1 for none.
    int id(const core::CompiledProgram& program);
    const std::vector<const ProgramDesc*>& programs(ProgramKind kind) const {
        return m_lists[size_t(kind)];
    }

  private:
    static constexpr size_t kKinds = size_t(ProgramKind::kCallable) + 1;
    std::array<std::map<const ProgramDesc*, int>, kKinds> m_ids;
    std::array<std::vector<const ProgramDesc*>, kKinds> m_lists;
};

/// What the generated kernel is specialised on.
struct KernelShape {
    bool groups = false;  // Group nodes (else every root is a GeometryGroup, or nested)
    bool transforms = false;
    bool selectors = false;
    bool generic_geometry = false;  // custom primitives, or a group not made only of triangles
    bool triangle_groups = false;   // some group is made only of triangles (GPU triangle BVH)
    bool spheres = false;           // some instance has built-in spheres
    bool curves = false;            // some instance has built-in curves
    bool exceptions = false;        // any exception enabled (else bounds checks are compiled out)
    bool print = false;
    bool occlusion = false;  // some bound module declares kUsesOccluded
    bool ray_control = false;  // ray flags, masks, ids or opaque geometry (needs_ray_control)
    bool motion = false;       // motion transforms or moving primitives (has_motion)
    unsigned max_depth = 1;
    unsigned attribute_bytes = 16;
};

KernelShape kernel_shape(const core::CompiledScene& scene);

/// The texts of the modules a table's programs come from: those given to the Context at
/// run time (`given`), else those embedded by lucent_add_programs; Error naming the
/// program, its file and the two ways to give a text when a module has neither.
using ModuleSourceList = std::vector<std::shared_ptr<const ModuleSource>>;
ModuleSourceList bound_module_sources(
    const ProgramTable& table,
    const std::map<const ModuleInfo*, std::shared_ptr<const ModuleSource>>& given);

/// The name of the kernel that runs ray-generation program `id` (ProgramTable's numbering):
/// the megakernel has one per bound ray-generation program, each calling it directly, each
/// compiled on its own (in parallel) into its own module.
std::string ray_generation_kernel(int id);

/// The line that defines ray-generation program `id`'s kernel, appended to the megakernel
/// source to make the unit that compiles it.
std::string ray_generation_kernel_definition(const ProgramTable& table, int id);

/// The megakernel source without its kernels: the runtime, every module of `modules`
/// (bound_module_sources) and the dispatch switches.
std::string generate_megakernel(const ProgramTable& table, const KernelShape& shape,
                                const ModuleSourceList& modules);

}  // namespace lucent::cuda

// The GPU binned-SAH triangle BVH builder: the host builder's algorithm (src/accel/bvh.cpp,
// Wald 2007, "On fast construction of SAH-based bounding volume hierarchies": 32 bins per
// axis on the centroids, fewer for small nodes, the SAH leaf test, the median split near the
// depth limit) run on the GPU as in Garanzha, Pantaleoni and McAllister 2011 ("Simpler and
// faster HLBVH with work queues"): the big nodes breadth-first, one level of the tree at a
// time over all the GPU, the small ones (up to GpuSahBuildParams::small_limit triangles)
// each by one warp, depth-first in shared memory. It makes the host's tree (the same splits,
// up to the order of triangles inside a leaf), so it traces as fast, and writes the layout of
// triangle_bvh.cuh directly. H-PLOC (bvh_build.cuh) builds faster trees that trace at
// 0.85-0.99x of this one (docs/performance.md).
//
// Every node owns a range [begin, begin + count) of the leaf order; a split gives child 0
// the front of it. The passes, one kernel each (gpu_bvh_builder.cpp launches them):
//  1. lucent_sah_init:      each triangle's box; the root's box and centroid box.
//  2. lucent_sah_bin:       per level: each place of the leaf order still in a big task adds
//     its triangle's box to its task's bins; a block stages the bins of the task it mostly
//     holds in shared memory (one global atomic per bin and block, not per triangle).
//  3. lucent_sah_split:     per level, a warp per big task: sweeps its bins, and makes two
//     children: big ones are tasks of the next level, small ones go to the small-task list,
//     one triangle is a leaf at once.
//  4. lucent_sah_partition: per level: each triangle moves to its child's part of the range
//     (places handed out per block, again staged in shared memory).
//  5. lucent_sah_small:     a warp per small task: loads its triangles into shared memory
//     and builds its whole subtree, node after node (bin, sweep, partition among its lanes).
//  6. lucent_sah_count:     bottom-up, the inner nodes and the SAH cost of every subtree.
//  7. lucent_sah_emit:      each inner node finds its depth-first place (child 0 right after
//     its parent, as the host's layout) and writes its 64-byte node; lucent_sah_triangles
//     copies the triangles into leaf order.
//
// Every kernel body is a plain function built for the host too: a per-thread pass is a
// function of (params, thread); a per-block pass a function of (params, block, shared
// memory) written as steps (sah_step) with a barrier after each. Tests run the whole build on
// the CPU, a thread at a time (gpu_sah_run_on_cpu).
//
// Files: bvh_sah_params.cuh (constants, tasks, parameters), bvh_sah_helpers.cuh (atomics,
// boxes, bins, the sweep), bvh_sah_levels.cuh (passes 1-4), bvh_sah_small.cuh (pass 5),
// bvh_sah_layout.cuh (passes 6, 7); this one: the passes in launch order, the CPU
// emulation and the kernels.
#pragma once

#include "lucent_gpu/bvh_sah_layout.cuh"
#include "lucent_gpu/bvh_sah_levels.cuh"
#include "lucent_gpu/bvh_sah_params.cuh"
#include "lucent_gpu/bvh_sah_small.cuh"

#if !LUCENT_GPU_CODE
#include <atomic>
#include <bit>
#include <cstring>
#endif

namespace lucent::gpu {

#if !LUCENT_GPU_CODE
/// The kernels in launch order, for the GPU launcher and the CPU emulation alike.
enum class GpuSahPass {
    kReset,
    kInit,
    kBin,
    kSplit,
    kPartition,
    kSmall,
    kCount,
    kEmit,
    kTriangles,
    kPassCount
};

/// Blocks and threads of each pass.
struct GpuSahShape {
    unsigned blocks, threads;
};

inline GpuSahShape gpu_sah_shape(GpuSahPass pass, unsigned n, unsigned small_limit) {
    auto over = [](size_t items, unsigned threads) {
        return GpuSahShape{unsigned((items + threads - 1) / threads), threads};
    };
    switch (pass) {
        case GpuSahPass::kReset:
            return GpuSahShape{1, kSahWarp};
        case GpuSahPass::kSplit:
            return GpuSahShape{gpu_sah_task_capacity(n, small_limit), kSahWarp};
        case GpuSahPass::kSmall: {
            const unsigned tasks = gpu_sah_small_capacity(n);
            return GpuSahShape{tasks < kSahSmallBlocks ? tasks : kSahSmallBlocks, kSahWarp};
        }
        case GpuSahPass::kCount:
        case GpuSahPass::kEmit:
            return over(2 * size_t(n) - 1, 128);
        case GpuSahPass::kTriangles:
            return over(n, 128);
        default:
            return over(n, kSahBlock);  // init, bin, partition: a thread per place
    }
}

/// Levels launched before the first read of a level's task count (each read waits for the
/// GPU; an empty level costs three launches that return at once): 1.5 times the levels of a
/// balanced tree down to the small tasks, and 2, as SAH trees are not balanced (Sponza,
/// Sibenik, the bunny and the dragon have 11-15 levels of big tasks for 15-17 launched).
inline unsigned gpu_sah_unread_levels(unsigned n, unsigned small_limit) {
    const unsigned balanced = unsigned(std::bit_width(n / small_limit));
    return balanced + balanced / 2 + 2;
}

/// Runs the passes of a build over n >= 1 triangles: run(pass, level) launches one,
/// tasks_of(parity) reads how many big tasks the level about to run has (after the first
/// gpu_sah_unread_levels levels, every 4 levels).
template <class Run, class TasksOf>
void gpu_sah_build_passes(unsigned n, unsigned small_limit, Run&& run, TasksOf&& tasks_of) {
    run(GpuSahPass::kReset, 0u);
    run(GpuSahPass::kInit, 0u);
    if (n > small_limit) {
        const unsigned unread = gpu_sah_unread_levels(n, small_limit);
        for (unsigned level = 0; level < kSahLevels; ++level) {
            if (level >= unread && (level - unread) % 4 == 0 && tasks_of(level & 1u) == 0) break;
            run(GpuSahPass::kBin, level);
            run(GpuSahPass::kSplit, level);
            run(GpuSahPass::kPartition, level);
        }
    }
    run(GpuSahPass::kSmall, 0u);
    run(GpuSahPass::kCount, 0u);
    run(GpuSahPass::kEmit, 0u);
    run(GpuSahPass::kTriangles, 0u);
}

/// Words of scratch a build of n triangles needs beyond its nodes (for the launcher and the
/// emulation alike).
struct GpuSahScratch {
    size_t task_capacity, small_capacity, bin_words;
};
inline GpuSahScratch gpu_sah_scratch(unsigned n, unsigned small_limit) {
    const size_t tasks = gpu_sah_task_capacity(n, small_limit);
    return GpuSahScratch{tasks, gpu_sah_small_capacity(n), tasks * kSahTaskBinWords};
}

/// One pass on the CPU, a thread at a time (the tests' emulation of the GPU build).
inline void gpu_sah_run_on_cpu(GpuSahBuildParams& p, GpuSahPass pass, unsigned level) {
    p.level = level;
    const GpuSahShape shape = gpu_sah_shape(pass, p.triangle_count, p.small_limit);
    for (unsigned b = 0; b < shape.blocks; ++b) {
        const unsigned first = b * shape.threads;
        switch (pass) {
            case GpuSahPass::kReset:
                for (unsigned t = 0; t < shape.threads; ++t) sah_reset(p, first + t);
                break;
            case GpuSahPass::kInit: {
                SahInitShared s;
                sah_init(p, b, shape.threads, s);
                break;
            }
            case GpuSahPass::kBin: {
                SahBinShared s;
                sah_bin(p, b, shape.threads, s);
                break;
            }
            case GpuSahPass::kSplit: {
                SahSplitShared s;
                sah_split(p, b, shape.threads, s);
                break;
            }
            case GpuSahPass::kPartition: {
                SahPartitionShared s;
                sah_partition(p, b, shape.threads, s);
                break;
            }
            case GpuSahPass::kSmall: {
                SahSmallShared s;
                sah_small(p, shape.threads, s);
                break;
            }
            case GpuSahPass::kCount:
                for (unsigned t = 0; t < shape.threads; ++t) sah_count(p, first + t);
                break;
            case GpuSahPass::kEmit:
                for (unsigned t = 0; t < shape.threads; ++t) sah_emit(p, first + t);
                break;
            case GpuSahPass::kTriangles:
                for (unsigned t = 0; t < shape.threads; ++t) sah_triangles(p, first + t);
                break;
            case GpuSahPass::kPassCount:
                break;
        }
    }
}
#endif

}  // namespace lucent::gpu

#if LUCENT_GPU_CODE
// The entry points the host launches (extern "C": unmangled names for cuModuleGetFunction).
#define LUCENT_SAH_THREAD_KERNEL(name, body, threads)                                              \
    extern "C" __global__ void __launch_bounds__(threads) name(lucent::gpu::GpuSahBuildParams p) { \
        lucent::gpu::body(p, blockIdx.x* blockDim.x + threadIdx.x);                                \
    }
#define LUCENT_SAH_BLOCK_KERNEL(name, body, shared, threads)                                       \
    extern "C" __global__ void __launch_bounds__(threads) name(lucent::gpu::GpuSahBuildParams p) { \
        __shared__ lucent::gpu::shared s;                                                          \
        lucent::gpu::body(p, blockIdx.x, blockDim.x, s);                                           \
    }
LUCENT_SAH_THREAD_KERNEL(lucent_sah_reset, sah_reset, 32)
LUCENT_SAH_BLOCK_KERNEL(lucent_sah_init, sah_init, SahInitShared, 256)
LUCENT_SAH_BLOCK_KERNEL(lucent_sah_bin, sah_bin, SahBinShared, 256)
LUCENT_SAH_BLOCK_KERNEL(lucent_sah_split, sah_split, SahSplitShared, 32)
LUCENT_SAH_BLOCK_KERNEL(lucent_sah_partition, sah_partition, SahPartitionShared, 256)
extern "C" __global__ void __launch_bounds__(32)
    lucent_sah_small(lucent::gpu::GpuSahBuildParams p) {
    __shared__ lucent::gpu::SahSmallShared s;
    lucent::gpu::sah_small(p, blockDim.x, s);
}
LUCENT_SAH_THREAD_KERNEL(lucent_sah_count, sah_count, 128)
LUCENT_SAH_THREAD_KERNEL(lucent_sah_emit, sah_emit, 128)
LUCENT_SAH_THREAD_KERNEL(lucent_sah_triangles, sah_triangles, 128)
#undef LUCENT_SAH_THREAD_KERNEL
#undef LUCENT_SAH_BLOCK_KERNEL
#endif  // LUCENT_GPU_CODE

// The GPU binned-SAH builder's pass 5 (bvh_sah_build.cuh): each small task's whole subtree,
// built by one warp in shared memory.
#pragma once

#include "lucent_gpu/bvh_sah_helpers.cuh"

namespace lucent::gpu {

// ---- 5: small tasks, a warp each ------------------------------------------------------------

struct SahSmallShared {
    unsigned have;                          // a task was taken
    GpuSahSmallTask task;                   // the small task (its node is the subtree's root)
    GpuSahSmallTask stack[kSahSmallStack];  // pending nodes, begin relative to the task's
    unsigned stack_size;
    GpuSahSmallTask node;  // the node being built, begin relative
    unsigned active;
    int box[6], cbox[6];
    SahFrame frame;
    SahBest best[3];
    SahDecision decision;
    unsigned child_node, fill[2];
    unsigned prim[kSahSmallMax];  // the task's triangles, by local index
    float3 lo[kSahSmallMax], hi[kSahSmallMax];
    unsigned short ids[kSahSmallMax];  // local indices in leaf order
    unsigned short ids_next[kSahSmallMax];
    unsigned bins[kSahTaskBinWords];
};

/// Builds the node in s.node (the task's triangles in shared memory): its boxes, bins, sweep
/// and decision, then its children pushed and its triangles partitioned between them.
LUCENT_HD inline void sah_small_node(const GpuSahBuildParams& p, unsigned threads,
                                     SahSmallShared& s) {
    const unsigned begin = s.node.begin, n = s.node.count;
    sah_step(threads, [&](unsigned t) {
        int box[6], cbox[6];
        sah_clear_box(box);
        sah_clear_box(cbox);
        for (unsigned j = t; j < n; j += threads) {
            const unsigned k = s.ids[begin + j];
            sah_include(box, s.lo[k], s.hi[k]);
            const float3 c = s.lo[k] + s.hi[k];
            sah_include(cbox, c, c);
        }
        sah_merge_box(s.box, box);
        sah_merge_box(s.cbox, cbox);
    });
    sah_step(threads, [&](unsigned t) {
        if (t != 0) return;
        float3 lo, hi;
        sah_box_of(s.box, lo, hi);
        sah_write_node_box(p, s.node.node, lo, hi);
        s.frame = sah_frame(s.cbox, n >= 2 ? sah_bins_for(p, n, s.node.depth) : 0u);
    });
    const unsigned nb = s.frame.bins;
    if (nb > 0) {
        sah_step(threads,
                 [&](unsigned t) { sah_clear_bins(s.bins, 3 * nb * kSahBinWords, t, threads); });
        sah_step(threads, [&](unsigned t) {
            for (unsigned j = t; j < n; j += threads) {
                const unsigned k = s.ids[begin + j];
                sah_add_to_bins(s.bins, s.frame, s.lo[k], s.hi[k]);
            }
        });
        sah_step(threads, [&](unsigned t) {
            sah_sweep_axes(s.bins, nb, s.best, t, threads);
        });
    }
    sah_step(threads, [&](unsigned t) {
        if (t != 0) return;
        float3 lo, hi;
        sah_box_of(s.box, lo, hi);
        s.decision = sah_decide(p, n, lo, hi, s.frame, s.best);
        const unsigned at = s.task.begin + begin;
        if (s.decision.decision == kSahDecideLeaf) {
            p.node_range[s.node.node] = make_uint2(at, n);
            return;
        }
        const unsigned c0 = sah_atomic_add(&p.counters[kSahNextNode], 2u);
        if (c0 + 2 > 2 * p.triangle_count - 1) {
            sah_atomic_first(&p.counters[kSahFault], kSahFaultNodes);
            s.decision.decision = kSahDecideLeaf;
            p.node_range[s.node.node] = make_uint2(at, n);
            return;
        }
        s.child_node = c0;
        s.fill[0] = s.fill[1] = 0;
        p.node_range[s.node.node] = make_uint2(c0, 0u);
        p.node_parent[c0] = s.node.node;
        p.node_parent[c0 + 1] = s.node.node;
        const unsigned left = s.decision.left_count;
        const GpuSahSmallTask child[2] = {{c0, begin, left, s.node.depth + 1},
                                          {c0 + 1, begin + left, n - left, s.node.depth + 1}};
        for (int side = 0; side < 2; ++side)
            p.node_range[child[side].node] =
                make_uint2(s.task.begin + child[side].begin, child[side].count);
        // The larger child waits, the smaller is built next: the stack stays short.
        const int first = child[0].count >= child[1].count ? 0 : 1;
        for (int q = 0; q < 2; ++q) {
            const int side = q == 0 ? first : 1 - first;
            if (child[side].count <= 1) continue;  // a leaf; its box comes with its triangle
            if (s.stack_size >= kSahSmallStack) {
                sah_atomic_first(&p.counters[kSahFault], kSahFaultSmallStack);
                continue;
            }
            s.stack[s.stack_size++] = child[side];
        }
    });
    if (s.decision.decision == kSahDecideLeaf) return;
    const unsigned left = s.decision.left_count;
    if (s.decision.decision == kSahDecideMedian) {  // the front half to child 0, in place
        sah_step(threads, [&](unsigned t) {
            for (unsigned side = t; side < 2; side += threads) {
                if ((side == 0 ? left : n - left) != 1) continue;
                const unsigned k = s.ids[begin + side * left];
                sah_write_node_box(p, s.child_node + side, s.lo[k], s.hi[k]);
            }
        });
        return;
    }
    sah_step(threads, [&](unsigned t) {
        for (unsigned j = t; j < n; j += threads) {
            const unsigned k = s.ids[begin + j];
            const unsigned side = sah_side(s.frame, s.decision.decision, s.lo[k], s.hi[k]);
            const unsigned at = side * left + sah_atomic_add(&s.fill[side], 1u);
            s.ids_next[begin + at] = (unsigned short)k;
            if ((side == 0 ? left : n - left) == 1)
                sah_write_node_box(p, s.child_node + side, s.lo[k], s.hi[k]);
        }
    });
    sah_step(threads, [&](unsigned t) {
        for (unsigned j = t; j < n; j += threads) s.ids[begin + j] = s.ids_next[begin + j];
    });
}

/// Per block of kSahWarp threads: takes small tasks one after another and builds each one's
/// subtree.
LUCENT_HD inline void sah_small(const GpuSahBuildParams& p, unsigned threads, SahSmallShared& s) {
    for (;;) {
        sah_step(threads, [&](unsigned t) {
            if (t != 0) return;
            const unsigned ti = sah_atomic_add(&p.counters[kSahSmallNext], 1u);
            s.have = ti < p.counters[kSahSmallCount] && ti < p.small_capacity;
            if (s.have) s.task = p.small[ti];
        });
        if (!s.have) return;
        const unsigned n = s.task.count;
        sah_step(threads, [&](unsigned t) {
            for (unsigned j = t; j < n; j += threads) {
                const unsigned prim = p.order[s.task.begin + j];
                s.prim[j] = prim;
                sah_prim_box(p, prim, s.lo[j], s.hi[j]);
                s.ids[j] = (unsigned short)j;
            }
            if (t != 0) return;
            s.stack[0] = GpuSahSmallTask{s.task.node, 0u, n, s.task.depth};
            s.stack_size = 1;
        });
        for (;;) {
            sah_step(threads, [&](unsigned t) {
                if (t != 0) return;
                s.active = s.stack_size > 0;
                if (!s.active) return;
                s.node = s.stack[--s.stack_size];
                sah_clear_box(s.box);
                sah_clear_box(s.cbox);
            });
            if (!s.active) break;
            sah_small_node(p, threads, s);
        }
        sah_step(threads, [&](unsigned t) {
            for (unsigned j = t; j < n; j += threads) p.order[s.task.begin + j] = s.prim[s.ids[j]];
        });
    }
}

}  // namespace lucent::gpu

// The GPU binned-SAH builder's passes 1-4 (bvh_sah_build.cuh): the counters and the root,
// then per level of big tasks: binning, the split of each task, and the partition of its
// triangles between its children.
#pragma once

#include "lucent_gpu/bvh_sah_helpers.cuh"

namespace lucent::gpu {

// ---- 0, 1: the counters, the root, triangle boxes ----------------------------------------

/// One thread: the counters, and the root as the one big task of level 0 or a small task.
LUCENT_HD inline void sah_reset(const GpuSahBuildParams& p, unsigned i) {
    if (i != 0) return;
    for (int c = 0; c < kSahCounterCount; ++c) p.counters[c] = 0;
    const unsigned n = p.triangle_count;
    p.counters[kSahNextNode] = 1;
    p.counters[kSahBadIndex] = kSahInvalid;
    p.node_parent[0] = kSahInvalid;
    p.node_range[0] = make_uint2(0u, n);
    if (n <= p.small_limit) {
        p.small[0] = GpuSahSmallTask{0u, 0u, n, 0u};
        p.counters[kSahSmallCount] = 1;
        return;
    }
    GpuSahTask& root = p.tasks[0][0];
    root.node = 0, root.begin = 0, root.count = n, root.depth = 0;
    sah_clear_box(root.box);
    sah_clear_box(root.cbox);
    root.bin_count = sah_bins_for(p, n, 0u);
    root.sent[0] = root.sent[1] = 0;
    sah_clear_bins(p.bins[0], kSahTaskBinWords, 0u, 1u);
    p.counters[kSahTaskCount] = 1;
}

struct SahInitShared {
    int box[6], cbox[6];  // the root's, staged
};

/// Per block of kSahBlock places: each triangle's box; the block's share of the root's
/// boxes, merged into the root once.
LUCENT_HD inline void sah_init(const GpuSahBuildParams& p, unsigned block, unsigned threads,
                               SahInitShared& s) {
    const unsigned n = p.triangle_count;
    sah_step(threads, [&](unsigned t) {
        if (t == 0) sah_clear_box(s.box), sah_clear_box(s.cbox);
    });
    sah_step(threads, [&](unsigned t) {
        const unsigned i = block * threads + t;
        if (i >= n) return;
        const uint3 v = sah_triangle(p, i);
        float3 lo = make_float3(0.0f, 0.0f, 0.0f), hi = lo;
        if (v.x < p.vertex_count && v.y < p.vertex_count && v.z < p.vertex_count) {
            const float3 a = p.positions[v.x], b = p.positions[v.y], c = p.positions[v.z];
            lo = fminf(a, fminf(b, c));
            hi = fmaxf(a, fmaxf(b, c));
        } else {
            sah_atomic_min(&p.counters[kSahBadIndex], i);
        }
        p.prim_lo[i] = make_float4(lo.x, lo.y, lo.z, 0.0f);
        p.prim_hi[i] = make_float4(hi.x, hi.y, hi.z, 0.0f);
        const bool big_root = n > p.small_limit;
        p.work[0][i] = i;
        p.place_task[0][i] = big_root ? 0u : kSahInvalid;
        p.order[i] = i;          // a small root reads its triangles from here
        p.node_arrivals[i] = 0;  // 2N - 1 nodes: two each (the bottom-up pass counts on them)
        if (n + i < 2 * n - 1) p.node_arrivals[n + i] = 0;
        if (!big_root) return;
        sah_grow_box(s.box, lo, hi);
        const float3 c = lo + hi;  // doubled centroid, as the host keeps them
        sah_grow_box(s.cbox, c, c);
    });
    sah_step(threads, [&](unsigned t) {
        if (t != 0 || n <= p.small_limit) return;
        sah_merge_box(p.tasks[0][0].box, s.box);
        sah_merge_box(p.tasks[0][0].cbox, s.cbox);
    });
}

// ---- 2: bins of the big tasks ---------------------------------------------------------------

struct SahBinShared {
    unsigned tasks;  // big tasks of this level
    unsigned main;   // the task whose bins the block stages, or kSahInvalid
    SahFrame frame;
    unsigned bins[kSahTaskBinWords];
};

/// The task the block holds most of, about: the one of its middle place, if it bins.
LUCENT_HD inline unsigned sah_main_task(const GpuSahBuildParams& p, unsigned parity, unsigned block,
                                        unsigned threads) {
    unsigned middle = block * threads + threads / 2;
    if (middle >= p.triangle_count) middle = p.triangle_count - 1;
    return p.place_task[parity][middle];
}

LUCENT_HD inline void sah_bin(const GpuSahBuildParams& p, unsigned block, unsigned threads,
                              SahBinShared& s) {
    const unsigned parity = p.level & 1u;
    sah_step(threads, [&](unsigned t) {
        const unsigned i = block * threads + t;
        if (i < p.triangle_count) p.place_task[parity ^ 1u][i] = kSahInvalid;  // the next level's
        if (t != 0) return;
        // The next level's tasks are made by this level's split.
        if (block == 0) p.counters[kSahTaskCount + (parity ^ 1u)] = 0;
        s.tasks = p.counters[kSahTaskCount + parity];
        s.main = kSahInvalid;
        if (s.tasks == 0) return;
        const unsigned main = sah_main_task(p, parity, block, threads);
        if (main == kSahInvalid || p.tasks[parity][main].bin_count == 0) return;
        s.main = main;
        s.frame = sah_frame(p.tasks[parity][main].cbox, p.tasks[parity][main].bin_count);
    });
    if (s.tasks == 0) return;  // an empty level: the build has no more big tasks
    const unsigned main = s.main;
    const unsigned words = main == kSahInvalid ? 0u : 3 * s.frame.bins * kSahBinWords;
    if (words > 0)
        sah_step(threads, [&](unsigned t) { sah_clear_bins(s.bins, words, t, threads); });
    sah_step(threads, [&](unsigned t) {
        const unsigned i = block * threads + t;
        if (i >= p.triangle_count) return;
        const unsigned ti = p.place_task[parity][i];
        if (ti == kSahInvalid) return;
        const GpuSahTask& task = p.tasks[parity][ti];
        if (task.bin_count == 0) return;  // a median split: no bins
        float3 lo, hi;
        sah_prim_box(p, p.work[parity][i], lo, hi);
        if (ti == main) {
            sah_add_to_bins(s.bins, s.frame, lo, hi);
        } else {
            sah_add_to_bins(p.bins[parity] + ti * kSahTaskBinWords,
                            sah_frame(task.cbox, task.bin_count), lo, hi);
        }
    });
    if (words == 0) return;
    sah_step(threads, [&](unsigned t) {  // one atomic per word of each bin that holds any
        unsigned* global = p.bins[parity] + main * kSahTaskBinWords;
        for (unsigned b = t; b < 3 * s.frame.bins; b += threads) {
            const unsigned* bin = s.bins + b * kSahBinWords;
            if (bin[0] == 0) continue;
            sah_atomic_add(global + b * kSahBinWords, bin[0]);
            sah_merge_box(reinterpret_cast<int*>(global + b * kSahBinWords + 1),
                          reinterpret_cast<const int*>(bin + 1));
        }
    });
}

// ---- 3: split, a warp per big task ----------------------------------------------------------

struct SahSplitShared {
    unsigned tasks;
    SahFrame frame;
    SahBest best[3];
    unsigned new_tasks[2];  // big children made, whose bins the warp clears
    unsigned bins[kSahTaskBinWords];
};

/// Makes a child of `count` triangles over [begin, ...): kSahInvalid for one triangle (a
/// leaf at once), a small task, or a big task of the next level (its bins cleared by the
/// caller).
LUCENT_HD inline unsigned sah_make_child(const GpuSahBuildParams& p, unsigned node, unsigned begin,
                                         unsigned count, unsigned depth) {
    p.node_range[node] = make_uint2(begin, count);  // a leaf unless it is split
    if (count <= 1) return kSahInvalid;
    if (count <= p.small_limit) {
        const unsigned si = sah_atomic_add(&p.counters[kSahSmallCount], 1u);
        if (si >= p.small_capacity) {
            sah_atomic_first(&p.counters[kSahFault], kSahFaultTasks);
            return kSahInvalid;
        }
        p.small[si] = GpuSahSmallTask{node, begin, count, depth};
        return kSahSmallBit | si;
    }
    const unsigned parity = (p.level + 1) & 1u;
    const unsigned ti = sah_atomic_add(&p.counters[kSahTaskCount + parity], 1u);
    if (ti >= p.task_capacity) {
        sah_atomic_first(&p.counters[kSahFault], kSahFaultTasks);
        return kSahInvalid;
    }
    GpuSahTask& t = p.tasks[parity][ti];
    t.node = node, t.begin = begin, t.count = count, t.depth = depth;
    sah_clear_box(t.box);
    sah_clear_box(t.cbox);
    t.bin_count = sah_bins_for(p, count, depth);
    t.sent[0] = t.sent[1] = 0;
    return ti;
}

LUCENT_HD inline void sah_split(const GpuSahBuildParams& p, unsigned block, unsigned threads,
                                SahSplitShared& s) {
    const unsigned parity = p.level & 1u;
    sah_step(threads, [&](unsigned t) {
        if (t != 0) return;
        s.tasks = p.counters[kSahTaskCount + parity];
        if (block < s.tasks) {
            const GpuSahTask& task = p.tasks[parity][block];
            s.frame = sah_frame(task.cbox, task.bin_count);
        }
    });
    if (block >= s.tasks) return;
    GpuSahTask& task = p.tasks[parity][block];
    const unsigned nb = s.frame.bins;
    if (nb > 0) {
        sah_step(threads, [&](unsigned t) {  // the bins into shared memory, for the sweeps
            const unsigned* global = p.bins[parity] + block * kSahTaskBinWords;
            for (unsigned w = t; w < 3 * nb * kSahBinWords; w += threads) s.bins[w] = global[w];
        });
        sah_step(threads, [&](unsigned t) {
            sah_sweep_axes(s.bins, nb, s.best, t, threads);
        });
    }
    sah_step(threads, [&](unsigned t) {
        if (t != 0) return;
        s.new_tasks[0] = s.new_tasks[1] = kSahInvalid;
        float3 lo, hi;
        sah_box_of(task.box, lo, hi);
        sah_write_node_box(p, task.node, lo, hi);
        const unsigned n = task.count;
        const SahDecision d = sah_decide(p, n, lo, hi, s.frame, s.best);
        task.decision = d.decision;
        task.left_count = d.left_count;
        if (d.decision == kSahDecideLeaf) {
            p.node_range[task.node] = make_uint2(task.begin, n);
            return;
        }
        const unsigned c0 = sah_atomic_add(&p.counters[kSahNextNode], 2u);
        if (c0 + 2 > 2 * p.triangle_count - 1) {
            sah_atomic_first(&p.counters[kSahFault], kSahFaultNodes);
            task.decision = kSahDecideLeaf;  // keeps the partition in bounds; the build fails
            return;
        }
        task.child_node = c0;
        p.node_range[task.node] = make_uint2(c0, 0u);
        p.node_parent[c0] = task.node;
        p.node_parent[c0 + 1] = task.node;
        const unsigned counts[2] = {d.left_count, n - d.left_count};
        for (unsigned side = 0; side < 2; ++side) {
            const unsigned child = sah_make_child(p, c0 + side, task.begin + side * d.left_count,
                                                  counts[side], task.depth + 1);
            task.child[side] = child;
            if (child != kSahInvalid && !(child & kSahSmallBit)) s.new_tasks[side] = child;
        }
    });
    sah_step(threads, [&](unsigned t) {
        for (unsigned side = 0; side < 2; ++side)
            if (s.new_tasks[side] != kSahInvalid)
                sah_clear_bins(p.bins[parity ^ 1u] + s.new_tasks[side] * kSahTaskBinWords,
                               kSahTaskBinWords, t, threads);
    });
}

// ---- 4: partition ---------------------------------------------------------------------------

struct SahPartitionShared {
    unsigned tasks;
    unsigned main;  // the task whose places the block hands out
    SahFrame frame;
    unsigned count[2], base[2];  // its triangles of this block going to each side
    int box[2][6], cbox[2][6];   // and their boxes, for big children
    unsigned slot[kSahBlock];    // each thread's place among its side's, or kSahInvalid
    unsigned char side[kSahBlock];
};

/// Puts triangle `prim` at place `at` of child `side` of task `t`: a leaf's triangle, a small
/// task's, or a big task's of the next level, whose boxes it grows unless `staged`.
LUCENT_HD inline void sah_place(const GpuSahBuildParams& p, const GpuSahTask& t, unsigned side,
                                unsigned at, unsigned prim, float3 lo, float3 hi, bool staged) {
    const unsigned child = t.child[side];
    if (child == kSahInvalid) {  // a one-triangle leaf
        sah_write_node_box(p, t.child_node + side, lo, hi);
        p.order[at] = prim;
        return;
    }
    if (child & kSahSmallBit) {
        p.order[at] = prim;
        return;
    }
    const unsigned parity = (p.level + 1) & 1u;
    p.work[parity][at] = prim;
    p.place_task[parity][at] = child;
    if (staged) return;
    GpuSahTask& c = p.tasks[parity][child];
    sah_grow_box(c.box, lo, hi);
    const float3 centroid = lo + hi;
    sah_grow_box(c.cbox, centroid, centroid);
}

LUCENT_HD inline bool sah_child_is_big(const GpuSahTask& t, unsigned side) {
    return t.child[side] != kSahInvalid && !(t.child[side] & kSahSmallBit);
}

LUCENT_HD inline void sah_partition(const GpuSahBuildParams& p, unsigned block, unsigned threads,
                                    SahPartitionShared& s) {
    const unsigned parity = p.level & 1u;
    sah_step(threads, [&](unsigned t) {
        if (t != 0) return;
        s.tasks = p.counters[kSahTaskCount + parity];
        s.main = kSahInvalid;
        if (s.tasks == 0) return;
        const unsigned main = sah_main_task(p, parity, block, threads);
        if (main == kSahInvalid) return;
        const GpuSahTask& task = p.tasks[parity][main];
        if (task.decision == kSahDecideLeaf || task.decision == kSahDecideMedian) return;
        s.main = main;
        s.frame = sah_frame(task.cbox, task.bin_count);
        for (int side = 0; side < 2; ++side) {
            s.count[side] = 0;
            sah_clear_box(s.box[side]);
            sah_clear_box(s.cbox[side]);
        }
    });
    if (s.tasks == 0) return;
    sah_step(threads, [&](unsigned t) {
        s.slot[t] = kSahInvalid;
        const unsigned i = block * threads + t;
        if (i >= p.triangle_count) return;
        const unsigned ti = p.place_task[parity][i];
        if (ti == kSahInvalid) return;
        GpuSahTask& task = p.tasks[parity][ti];
        const unsigned prim = p.work[parity][i];
        float3 lo, hi;
        sah_prim_box(p, prim, lo, hi);
        if (task.decision == kSahDecideLeaf) {  // only after a fault: keeps the places
            p.order[i] = prim;
            return;
        }
        if (task.decision == kSahDecideMedian) {  // the front half to child 0, in place
            sah_place(p, task, i - task.begin < task.left_count ? 0u : 1u, i, prim, lo, hi, false);
            return;
        }
        const unsigned side =
            ti == s.main ? sah_side(s.frame, task.decision, lo, hi)
                         : sah_side(sah_frame(task.cbox, task.bin_count), task.decision, lo, hi);
        if (ti != s.main) {
            const unsigned at =
                task.begin + side * task.left_count + sah_atomic_add(&task.sent[side], 1u);
            sah_place(p, task, side, at, prim, lo, hi, false);
            return;
        }
        s.side[t] = (unsigned char)side;
        s.slot[t] = sah_atomic_add(&s.count[side], 1u);
        if (sah_child_is_big(task, side)) {
            sah_grow_box(s.box[side], lo, hi);
            const float3 centroid = lo + hi;
            sah_grow_box(s.cbox[side], centroid, centroid);
        }
    });
    if (s.main == kSahInvalid) return;
    sah_step(threads, [&](unsigned t) {  // the block's places in each child, and its boxes
        if (t != 0) return;
        GpuSahTask& task = p.tasks[parity][s.main];
        for (unsigned side = 0; side < 2; ++side) {
            if (s.count[side] == 0) continue;
            s.base[side] = sah_atomic_add(&task.sent[side], s.count[side]);
            if (!sah_child_is_big(task, side)) continue;
            GpuSahTask& c = p.tasks[parity ^ 1u][task.child[side]];
            sah_merge_box(c.box, s.box[side]);
            sah_merge_box(c.cbox, s.cbox[side]);
        }
    });
    sah_step(threads, [&](unsigned t) {
        if (s.slot[t] == kSahInvalid) return;
        const unsigned i = block * threads + t;
        const GpuSahTask& task = p.tasks[parity][s.main];
        const unsigned side = s.side[t];
        const unsigned prim = p.work[parity][i];
        float3 lo, hi;
        sah_prim_box(p, prim, lo, hi);
        sah_place(p, task, side, task.begin + side * task.left_count + s.base[side] + s.slot[t],
                  prim, lo, hi, true);
    });
}

}  // namespace lucent::gpu

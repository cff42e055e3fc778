#include "cuda/accel/gpu_triangle_bvh.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <string>

#include "lucent/error.h"

namespace lucent::cuda {

namespace {

constexpr float kEmptyLo = 3.0e38f, kEmptyHi = -3.0e38f;  // a box no ray enters
constexpr uint32_t kNoParent = 0xffffffffu;

uint3 triangle(std::span<const uint3> indices, size_t i) {
    return indices.empty() ? make_uint3(3 * (unsigned)i, 3 * (unsigned)i + 1, 3 * (unsigned)i + 2)
                           : indices[i];
}

/// Writes the boxes of an inner node's children (Aila-Laine's node layout).
void set_boxes(float4* n, float3 lo0, float3 hi0, float3 lo1, float3 hi1) {
    n[0] = make_float4(lo0.x, hi0.x, lo0.y, hi0.y);
    n[1] = make_float4(lo1.x, hi1.x, lo1.y, hi1.y);
    n[2] = make_float4(lo0.z, hi0.z, lo1.z, hi1.z);
}

void set_children(float4* n, int child0, int child1) {
    n[3] = make_float4(std::bit_cast<float>(child0), std::bit_cast<float>(child1), 0.0f, 0.0f);
}

/// The binned-SAH binary BVH the layout is made from, after checking the input: every vertex
/// index in range, no more triangles than a leaf reference holds, max_leaf_size within
/// 1..kGpuMaxLeafSize, and a depth the traversal stack holds.
accel::Bvh build_source_bvh(std::span<const float3> positions, std::span<const uint3> indices,
                            const GpuBvhBuildOptions& options, accel::BuildStats& stats) {
    const std::string layout = "GPU triangle BVH";  // names it in the errors
    const size_t tri_count = indices.empty() ? positions.size() / 3 : indices.size();
    if (tri_count > gpu::kGpuLeafFirstMask)
        throw Error(layout + ": " + std::to_string(tri_count) +
                    " triangles, the layout holds at most " +
                    std::to_string(gpu::kGpuLeafFirstMask));
    if (options.max_leaf_size < 1 || options.max_leaf_size > gpu::kGpuMaxLeafSize)
        throw Error(layout + ": max_leaf_size must be 1.." + std::to_string(gpu::kGpuMaxLeafSize));

    // Triangle boxes.
    std::vector<Aabb> boxes(tri_count);
    for (size_t i = 0; i < tri_count; ++i) {
        const uint3 t = triangle(indices, i);
        if (t.x >= positions.size() || t.y >= positions.size() || t.z >= positions.size())
            throw Error(layout + ": triangle " + std::to_string(i) +
                        " has a vertex index out of range");
        const float3 a = positions[t.x], b = positions[t.y], c = positions[t.z];
        boxes[i].lo = fminf(a, fminf(b, c));
        boxes[i].hi = fmaxf(a, fmaxf(b, c));
    }

    accel::BuildOptions build;
    build.bins = options.bins;
    build.max_leaf_size = options.max_leaf_size;
    build.traversal_cost = options.traversal_cost;
    build.intersection_cost = options.intersection_cost;
    accel::Bvh bvh;
    const accel::SplitTriangles split{positions, indices};
    bvh.build(boxes, build, &stats, options.spatial_splits ? &split : nullptr);
    if (stats.depth + 2 >= (unsigned)gpu::kGpuStackSize)
        throw Error(layout + ": depth " + std::to_string(stats.depth) +
                    " exceeds the traversal stack (" + std::to_string(gpu::kGpuStackSize) + ")");
    return bvh;
}

/// Appends the triangles of a leaf of `bvh` in leaf order (three float4 each, w = 0) and
/// their input indices; returns the index of the first.
unsigned append_leaf_triangles(std::span<const float3> positions, std::span<const uint3> indices,
                               const accel::Bvh& bvh, const accel::BvhNode& leaf,
                               std::vector<float4>& triangles,
                               std::vector<uint32_t>& triangle_ids) {
    const unsigned first = (unsigned)triangle_ids.size();
    for (uint32_t k = 0; k < leaf.count; ++k) {
        const uint32_t prim = bvh.prim_order()[leaf.first + k];
        const uint3 t = triangle(indices, prim);
        triangles.push_back(make_float4(positions[t.x], 0.0f));
        triangles.push_back(make_float4(positions[t.y], 0.0f));
        triangles.push_back(make_float4(positions[t.z], 0.0f));
        triangle_ids.push_back(prim);
    }
    return first;
}

}  // namespace

GpuTriangleBvh build_gpu_triangle_bvh(std::span<const float3> positions,
                                      std::span<const uint3> indices,
                                      const GpuBvhBuildOptions& options) {
    const size_t tri_count = indices.empty() ? positions.size() / 3 : indices.size();
    accel::BuildStats bs;
    const accel::Bvh bvh = build_source_bvh(positions, indices, options, bs);

    const auto start = std::chrono::steady_clock::now();
    GpuTriangleBvh out;
    out.stats.build_ms = bs.build_ms;
    out.stats.sah_cost = bs.sah_cost;
    out.stats.depth = bs.depth;
    out.triangles.reserve(3 * tri_count);
    out.triangle_ids.reserve(tri_count);

    const std::vector<accel::BvhNode>& nodes = bvh.nodes();
    auto emit_leaf = [&](const accel::BvhNode& n) {
        if (n.count > (uint32_t)gpu::kGpuMaxLeafSize)
            throw Error("GPU triangle BVH: a leaf of " + std::to_string(n.count) + " triangles");
        // Spatial splits add references: the leaf's slots must still fit a reference.
        if (out.triangle_ids.size() + n.count > size_t(gpu::kGpuLeafFirstMask))
            throw Error("GPU triangle BVH: " + std::to_string(out.triangle_ids.size() + n.count) +
                        " leaf slots with spatial splits, the layout holds at most " +
                        std::to_string(gpu::kGpuLeafFirstMask) +
                        "; build without spatial splits (GpuBvhBuildOptions::spatial_splits)");
        const unsigned first =
            append_leaf_triangles(positions, indices, bvh, n, out.triangles, out.triangle_ids);
        ++out.stats.leaf_count;
        return gpu::gpu_make_leaf(first, n.count);
    };
    // Depth-first, child 0 first: a node's first child follows it in memory.
    auto emit = [&](auto&& self, uint32_t index) -> int {
        const accel::BvhNode& n = nodes[index];
        if (n.count > 0) return emit_leaf(n);
        const size_t at = out.nodes.size();
        out.nodes.resize(at + gpu::kGpuNodeFloat4s);
        out.parents.push_back(kNoParent);  // set by the parent below
        const accel::BvhNode& c0 = nodes[n.first];
        const accel::BvhNode& c1 = nodes[n.first + 1];
        set_boxes(&out.nodes[at], c0.lo, c0.hi, c1.lo, c1.hi);
        const int r0 = self(self, n.first);
        const int r1 = self(self, n.first + 1);
        const uint32_t me = uint32_t(at / gpu::kGpuNodeFloat4s);
        if (r0 >= 0) out.parents[r0 / gpu::kGpuNodeFloat4s] = me << 1;
        if (r1 >= 0) out.parents[r1 / gpu::kGpuNodeFloat4s] = me << 1 | 1u;
        set_children(&out.nodes[at], r0, r1);
        return (int)at;
    };

    const float3 empty_lo = make_float3(kEmptyLo), empty_hi = make_float3(kEmptyHi);
    if (nodes.empty()) {
        // No triangles: a root whose two boxes are empty.
        out.nodes.resize(gpu::kGpuNodeFloat4s);
        out.parents.assign(1, kNoParent);
        set_boxes(out.nodes.data(), empty_lo, empty_hi, empty_lo, empty_hi);
        set_children(out.nodes.data(), gpu::gpu_make_leaf(0, 1), gpu::gpu_make_leaf(0, 1));
    } else if (nodes[0].count > 0) {
        // The whole mesh is one leaf: the root is inner, its second box is empty.
        out.nodes.resize(gpu::kGpuNodeFloat4s);
        out.parents.assign(1, kNoParent);
        set_boxes(out.nodes.data(), nodes[0].lo, nodes[0].hi, empty_lo, empty_hi);
        const int leaf = emit_leaf(nodes[0]);
        set_children(out.nodes.data(), leaf, leaf);
    } else {
        out.nodes.reserve(gpu::kGpuNodeFloat4s * nodes.size() / 2);
        emit(emit, 0);
    }
    out.stats.node_count = out.nodes.size() / gpu::kGpuNodeFloat4s;
    out.stats.convert_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return out;
}

std::vector<float3> layout_input_triangles(std::span<const float4> triangles,
                                           std::span<const uint32_t> triangle_ids) {
    const size_t count = triangle_ids.size();
    if (triangles.size() != size_t(gpu::kGpuTriangleFloat4s) * count)
        throw Error("GPU triangle BVH: " + std::to_string(triangles.size()) +
                    " triangle float4s for " + std::to_string(count) + " triangle ids");
    std::vector<float3> positions(3 * count);
    std::vector<bool> seen(count, false);
    for (size_t slot = 0; slot < count; ++slot) {
        const uint32_t id = triangle_ids[slot];
        if (id >= count || seen[id])
            throw Error("GPU triangle BVH: leaf slot " + std::to_string(slot) + " holds triangle " +
                        std::to_string(id) + ", " +
                        (id >= count ? "out of range" : "already in another slot") +
                        "; the input triangles come back only from a layout without "
                        "spatial splits");
        seen[id] = true;
        for (int v = 0; v < 3; ++v) {
            const float4 p = triangles[gpu::kGpuTriangleFloat4s * slot + v];
            positions[3 * size_t(id) + v] = make_float3(p.x, p.y, p.z);
        }
    }
    return positions;
}

void upload_gpu_triangle_bvh(const GpuTriangleBvh& bvh, GpuTriangleBvhDevice& device) {
    device.nodes.upload(std::span<const float4>(bvh.nodes));
    device.triangles.upload(std::span<const float4>(bvh.triangles));
    device.triangle_ids.upload(std::span<const uint32_t>(bvh.triangle_ids));
    device.parents.upload(std::span<const uint32_t>(bvh.parents));
    device.node_count = bvh.nodes.size() / gpu::kGpuNodeFloat4s;
    device.triangle_count = bvh.triangle_ids.size();
}

}  // namespace lucent::cuda

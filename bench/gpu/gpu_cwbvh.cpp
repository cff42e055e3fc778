#include "bench/gpu/gpu_cwbvh.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <string>

#include "accel/wide_collapse.h"
#include "lucent/error.h"

namespace lucent::cuda {

namespace {

constexpr int kMinExponent = -126;             // the step 2^e is a normal float
constexpr int kMaxExponent = 119;              // 255 * 2^e stays finite
constexpr double kFloatIntegers = 16777216.0;  // 2^24

unsigned pack4(const unsigned (&bytes)[gpu::kCwbvhArity], int first) {
    return bytes[first] | bytes[first + 1] << 8 | bytes[first + 2] << 16 | bytes[first + 3] << 24;
}

float as_float(unsigned bits) {
    return std::bit_cast<float>(bits);
}

struct Emitter {
    std::span<const float3> positions;
    std::span<const uint3> indices;
    const accel::Bvh& bvh;
    const accel::WideCollapse& plan;
    GpuCwbvh& out;
    unsigned max_depth = 0;

    /// Writes node `index`, standing for binary node `bnode`, then its children.
    void emit(size_t index, uint32_t bnode, unsigned depth) {
        max_depth = std::max(max_depth, depth);
        const auto& bn = bvh.nodes();
        const accel::BvhNode& box = bn[bnode];
        uint32_t slot_kid[accel::kWideArity];
        plan.children_by_octant(bnode, slot_kid);
        const CwbvhAxisGrid grid[3] = {cwbvh_axis_grid(box.lo.x, box.hi.x),
                                       cwbvh_axis_grid(box.lo.y, box.hi.y),
                                       cwbvh_axis_grid(box.lo.z, box.hi.z)};
        double step[3];
        for (int k = 0; k < 3; ++k) step[k] = gpu::cwbvh_step(grid[k].biased_exponent);

        unsigned inner = 0, meta[gpu::kCwbvhArity] = {};
        unsigned qlo[3][gpu::kCwbvhArity], qhi[3][gpu::kCwbvhArity];
        const size_t child_base = out.nodes.size() / gpu::kCwbvhNodeFloat4s;
        const size_t triangle_base = out.triangle_ids.size();
        int inner_count = 0;
        for (int i = 0; i < gpu::kCwbvhArity; ++i) {
            if (slot_kid[i] == accel::WideCollapse::kNoChild) {  // empty: inside-out box
                for (int k = 0; k < 3; ++k) qlo[k][i] = gpu::kCwbvhQuantMax, qhi[k][i] = 0;
                continue;
            }
            const accel::BvhNode& kid = bn[slot_kid[i]];
            const float lo[3] = {kid.lo.x, kid.lo.y, kid.lo.z},
                        hi[3] = {kid.hi.x, kid.hi.y, kid.hi.z};
            constexpr double kQuantMax = gpu::kCwbvhQuantMax;
            for (int k = 0; k < 3; ++k) {
                // Outwards: floor for lo, ceil for hi, in double where both are exact.
                qlo[k][i] = (unsigned)std::clamp(
                    std::floor((double(lo[k]) - grid[k].origin) / step[k]), 0.0, kQuantMax);
                qhi[k][i] = (unsigned)std::clamp(
                    std::ceil((double(hi[k]) - grid[k].origin) / step[k]), 0.0, kQuantMax);
            }
            if (kid.count > 0) {
                const unsigned first = append_leaf_triangles(positions, indices, bvh, kid,
                                                             out.triangles, out.triangle_ids);
                // Unary count over the offset; at most 8 leaves of at most 3 triangles keep
                // the offsets below 24.
                meta[i] = ((1u << kid.count) - 1u) << 5 | unsigned(first - triangle_base);
                ++out.stats.leaf_count;
            } else {
                inner |= 1u << i;
                meta[i] = 1u << 5 | (gpu::kCwbvhInnerBit + unsigned(i));
                ++inner_count;
            }
        }
        out.nodes.resize(out.nodes.size() + gpu::kCwbvhNodeFloat4s * size_t(inner_count));

        float4* w = &out.nodes[gpu::kCwbvhNodeFloat4s * index];
        w[0] = make_float4(grid[0].origin, grid[1].origin, grid[2].origin,
                           as_float(grid[0].biased_exponent | grid[1].biased_exponent << 8 |
                                    grid[2].biased_exponent << 16 | inner << 24));
        w[1] = make_float4(as_float(unsigned(child_base)), as_float(unsigned(triangle_base)),
                           as_float(pack4(meta, 0)), as_float(pack4(meta, 4)));
        for (int k = 0; k < 3; ++k)
            w[2 + k] = make_float4(as_float(pack4(qlo[k], 0)), as_float(pack4(qlo[k], 4)),
                                   as_float(pack4(qhi[k], 0)), as_float(pack4(qhi[k], 4)));

        int rank = 0;
        for (int i = 0; i < gpu::kCwbvhArity; ++i)
            if (inner & (1u << i)) emit(child_base + size_t(rank++), slot_kid[i], depth + 1);
    }
};

}  // namespace

CwbvhAxisGrid cwbvh_axis_grid(float lo, float hi) {
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo <= hi))
        throw Error("GPU compressed wide BVH: a box from " + std::to_string(lo) + " to " +
                    std::to_string(hi) + " (a vertex that is not finite?)");
    // The smallest step that covers the extent in 255 steps and keeps origin / step within
    // the floats' integers; then up, one power of two at a time, until the floored origin
    // still reaches hi.
    int e = kMinExponent;
    int exponent;
    const double extent = double(hi) - double(lo);
    if (extent > 0.0) {
        std::frexp(extent / gpu::kCwbvhQuantMax, &exponent);  // < 2^exponent
        e = std::max(e, exponent - 1);
    }
    const double magnitude = std::max(std::fabs(double(lo)), std::fabs(double(hi)));
    if (magnitude > 0.0) {
        std::frexp(magnitude, &exponent);  // magnitude < 2^exponent
        e = std::max(e, exponent - 23);
    }
    for (; e <= kMaxExponent; ++e) {
        const double step = std::ldexp(1.0, e);
        const double origin = std::floor(double(lo) / step) * step;
        if (std::ceil((double(hi) - origin) / step) > gpu::kCwbvhQuantMax) continue;
        if (std::fabs(origin) / step + gpu::kCwbvhQuantMax >= kFloatIntegers) continue;
        return {float(origin), unsigned(e + 127)};
    }
    throw Error("GPU compressed wide BVH: no grid spans " + std::to_string(lo) + " to " +
                std::to_string(hi));
}

GpuCwbvh build_gpu_cwbvh(std::span<const float3> positions, std::span<const uint3> indices,
                         const GpuBvhBuildOptions& options) {
    accel::BuildStats bs;
    const accel::Bvh bvh = build_gpu_source_bvh(
        positions, indices, options, "GPU compressed wide BVH", gpu::kCwbvhMaxLeafSize, bs);
    const auto start = std::chrono::steady_clock::now();
    GpuCwbvh out;
    out.stats.builder = "binned SAH (host), optimal 8-wide collapse";
    out.stats.build_ms = bs.build_ms;
    out.stats.sah_cost = bs.sah_cost;
    out.nodes.resize(gpu::kCwbvhNodeFloat4s);  // the root
    if (bvh.empty()) {
        // No triangles: a root with eight empty slots.
        const unsigned inside_out[gpu::kCwbvhArity] = {255, 255, 255, 255, 255, 255, 255, 255};
        out.nodes[0] = make_float4(0.0f, 0.0f, 0.0f, as_float(127u | 127u << 8 | 127u << 16));
        out.nodes[1] = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
        for (int k = 0; k < 3; ++k)
            out.nodes[2 + k] = make_float4(as_float(pack4(inside_out, 0)),
                                           as_float(pack4(inside_out, 4)), 0.0f, 0.0f);
    } else {
        // A node costs its area, a leaf its triangles times theirs, in the SAH's units.
        const float leaf_cost = options.intersection_cost / options.traversal_cost;
        const accel::WideCollapse plan(bvh, [&](uint32_t count) { return leaf_cost * count; });
        Emitter emitter{positions, indices, bvh, plan, out};
        emitter.emit(0, 0, 1);
        out.stats.depth = emitter.max_depth;
    }
    out.stats.node_count = out.nodes.size() / gpu::kCwbvhNodeFloat4s;
    out.stats.convert_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return out;
}

void upload_gpu_cwbvh(const GpuCwbvh& bvh, GpuCwbvhDevice& device) {
    device.nodes.upload(std::span<const float4>(bvh.nodes));
    device.triangles.upload(std::span<const float4>(bvh.triangles));
    device.triangle_ids.upload(std::span<const uint32_t>(bvh.triangle_ids));
}

}  // namespace lucent::cuda

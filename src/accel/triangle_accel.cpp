// TriangleAccel: build (binned SAH over triangle boxes), collapse of the binary tree into
// 8-wide nodes with SoA leaves, and refit. The queries are in triangle_traverse.cpp.
#include <algorithm>
#include <chrono>
#include <string>

#include "accel/triangle_accel.h"
#include "accel/wide_bvh.h"
#include "accel/wide_collapse.h"
#include "lucent/error.h"

namespace lucent::accel {

namespace {

// The SAH prices a leaf by blocks of four triangles, as Embree's builders do for Triangle4
// leaves, although a leaf of five to eight is one 8-lane test: pricing those at one test
// made leaves of eight everywhere and closest-hit rays 20 % slower on Sponza (a leaf of
// eight is five cache lines, and its box is larger); 1.25-1.75 tests lost 9-15 % on Sponza
// and 1.5 gained 2-4 % on Sibenik. At 2, the leaves the SAH still wants above four
// triangles are tested at once.
constexpr uint32_t kSahBlockTriangles = 4;

uint3 triangle(std::span<const uint3> indices, size_t i) {
    if (!indices.empty()) return indices[i];
    uint32_t b = (uint32_t)(3 * i);
    return make_uint3(b, b + 1, b + 2);
}

std::vector<Aabb> triangle_boxes(std::span<const float3> vertices, std::span<const uint3> indices,
                                 size_t count) {
    std::vector<Aabb> boxes(count);
    for (size_t i = 0; i < count; ++i) {
        uint3 t = triangle(indices, i);
        float3 a = vertices[t.x], b = vertices[t.y], c = vertices[t.z];
        boxes[i].lo = fminf(a, fminf(b, c));
        boxes[i].hi = fmaxf(a, fmaxf(b, c));
    }
    return boxes;
}

/// Depth-first emission of the wide tree, with the children WideCollapse chooses.
struct Collapser {
    const Bvh& binary;
    const WideCollapse& plan;
    std::span<const float3> vertices;
    std::span<const uint3> indices;
    WideNodes& nodes;
    TriangleBlocks<4>& blocks4;
    TriangleBlocks<8>& blocks8;
    unsigned max_depth = 0;

    uint32_t emit_leaf(const BvhNode& leaf) {
        const uint32_t index = leaf.count > kNarrowLeafTriangles ? fill_block(blocks8, leaf)
                                                                 : fill_block(blocks4, leaf);
        return kLeafBit | ((leaf.count - 1) << kLeafCountShift) | index;
    }

    /// Appends the leaf's block to `blocks` and returns its index.
    template <int kLanes>
    uint32_t fill_block(TriangleBlocks<kLanes>& blocks, const BvhNode& leaf) {
        if (blocks.size() > kLeafIndexMask)
            throw Error("TriangleAccel: more than " + std::to_string(kLeafIndexMask + 1) +
                        " leaves of " + std::to_string(kLanes) +
                        "-lane blocks, more than a leaf reference holds; split the mesh "
                        "into several GeometryTriangles");
        const auto index = uint32_t(blocks.size());
        TriangleBlock<kLanes>& block = blocks.emplace_back();
        for (uint32_t lane = 0; lane < kLanes; ++lane) {
            // Padding lanes repeat the first triangle; traversal masks them by the count.
            uint32_t prim = binary.prim_order()[leaf.first + (lane < leaf.count ? lane : 0)];
            uint3 t = triangle(indices, prim);
            const float3 v[3] = {vertices[t.x], vertices[t.y], vertices[t.z]};
            for (int k = 0; k < 3; ++k) {
                block.vertex[k][0][lane] = v[k].x;
                block.vertex[k][1][lane] = v[k].y;
                block.vertex[k][2][lane] = v[k].z;
            }
            block.prim[lane] = prim;
        }
        return index;
    }

    uint32_t emit_node(uint32_t bnode, unsigned depth) {
        max_depth = std::max(max_depth, depth);
        const auto& bn = binary.nodes();
        uint32_t kids[kWideArity];
        const int n = plan.children(bnode, kids);
        const uint32_t me = (uint32_t)nodes.size();
        nodes.emplace_back();
        for (int i = 0; i < kWideArity; ++i) {
            WideNode& w = nodes[me];
            if (i >= n) {
                for (int k = 0; k < 3; ++k) {
                    w.planes[k][0][i] = kInfinity;
                    w.planes[k][1][i] = -kInfinity;
                }
                w.child[i] = kEmptyChild;
                continue;
            }
            const BvhNode& c = bn[kids[i]];
            w.planes[0][0][i] = c.lo.x, w.planes[0][1][i] = c.hi.x;
            w.planes[1][0][i] = c.lo.y, w.planes[1][1][i] = c.hi.y;
            w.planes[2][0][i] = c.lo.z, w.planes[2][1][i] = c.hi.z;
            uint32_t ref = c.count > 0 ? emit_leaf(c) : emit_node(kids[i], depth + 1);
            nodes[me].child[i] = ref;  // `w` may dangle: emit_node grows `nodes`
        }
        return me;
    }
};

}  // namespace

void TriangleAccel::Impl::collapse(std::span<const float3> vertices,
                                   std::span<const uint3> indices) {
    nodes.clear();
    blocks4.clear();
    blocks8.clear();
    wide_depth = 0;
    if (binary.empty()) {
        WideNode& root = nodes.emplace_back();
        for (int i = 0; i < kWideArity; ++i) {
            for (int k = 0; k < 3; ++k) {
                root.planes[k][0][i] = kInfinity;
                root.planes[k][1][i] = -kInfinity;
            }
            root.child[i] = kEmptyChild;
        }
        return;
    }
    nodes.reserve(binary.nodes().size() / 4 + 1);
    // Costs: 1 per wide node entered, 1 per block of kSahBlockTriangles, times the area.
    const WideCollapse plan(binary, [](uint32_t count) {
        return (count + kSahBlockTriangles - 1) / kSahBlockTriangles;
    });
    Collapser c{binary, plan, vertices, indices, nodes, blocks4, blocks8};
    c.emit_node(0, 1);
    wide_depth = c.max_depth;
}

TriangleAccel::TriangleAccel() : m_impl(std::make_unique<Impl>()) {
    m_impl->collapse({}, {});
}
TriangleAccel::~TriangleAccel() = default;
TriangleAccel::TriangleAccel(TriangleAccel&&) noexcept = default;
TriangleAccel& TriangleAccel::operator=(TriangleAccel&&) noexcept = default;

void TriangleAccel::build(std::span<const float3> vertices, std::span<const uint3> indices,
                          const BuildOptions& options, BuildStats* stats) {
    auto start = std::chrono::steady_clock::now();
    if (!m_impl) m_impl = std::make_unique<Impl>();
    const size_t count = indices.empty() ? vertices.size() / 3 : indices.size();
    m_impl->triangle_count = count;
    std::vector<Aabb> boxes = triangle_boxes(vertices, indices, count);
    BuildOptions opt = options;
    // A leaf is one block of up to eight triangles, tested in one SIMD pass.
    opt.max_leaf_size = opt.max_leaf_size > 0 ? std::min(opt.max_leaf_size, (int)kMaxLeafTriangles)
                                              : (int)kMaxLeafTriangles;
    BuildStats binary_stats;
    m_impl->binary.m_block_size = kSahBlockTriangles;
    const SplitTriangles split{vertices, indices};
    m_impl->binary.build(boxes, opt, &binary_stats, opt.spatial_splits ? &split : nullptr);
    m_impl->sah_cost = binary_stats.sah_cost;
    m_impl->collapse(vertices, indices);
    if (stats) {
        *stats = binary_stats;
        stats->build_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        stats->node_count = m_impl->nodes.size();
        stats->leaf_count = m_impl->blocks4.size() + m_impl->blocks8.size();
        stats->large_leaf_count = m_impl->blocks8.size();
    }
}

void TriangleAccel::refit(std::span<const float3> vertices, std::span<const uint3> indices) {
    if (!m_impl) return;
    std::vector<Aabb> boxes = triangle_boxes(vertices, indices, m_impl->triangle_count);
    m_impl->binary.refit(boxes);
    m_impl->sah_cost = m_impl->binary.sah_cost();
    m_impl->collapse(vertices, indices);
}

size_t TriangleAccel::triangle_count() const {
    return m_impl ? m_impl->triangle_count : 0;
}

Aabb TriangleAccel::bounds() const {
    if (!m_impl) return Aabb{make_float3(kInfinity), make_float3(-kInfinity)};
    return m_impl->binary.bounds();
}

std::vector<Aabb> TriangleAccel::leaf_boxes() const {
    std::vector<Aabb> boxes;
    if (!m_impl) return boxes;
    for (const WideNode& node : m_impl->nodes)
        for (int c = 0; c < kWideArity; ++c) {
            const uint32_t ref = node.child[c];
            if (ref == kEmptyChild || !is_leaf(ref)) continue;
            boxes.push_back(Aabb{
                make_float3(node.planes[0][0][c], node.planes[1][0][c], node.planes[2][0][c]),
                make_float3(node.planes[0][1][c], node.planes[1][1][c], node.planes[2][1][c])});
        }
    return boxes;
}

double TriangleAccel::sah_cost() const {
    return m_impl ? m_impl->sah_cost : 0.0;
}

}  // namespace lucent::accel

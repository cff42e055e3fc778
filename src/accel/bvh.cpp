// Binned SAH builder for the binary BVH (Wald 2007, "On fast construction of SAH-based
// bounding volume hierarchies"), with refit and the SAH cost of a finished tree.
#include "accel/bvh.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <thread>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace lucent::accel {

namespace {

constexpr int kMaxBins = 64;
constexpr unsigned kMaxDepth = 60;  // the traversal stacks hold 64 entries

/// A primitive's box and index, packed so partitioning moves 32 contiguous bytes.
struct PrimRef {
    float lo[3];
    uint32_t id;
    float hi[3];
    float pad;
};

struct Box {
    float lo[3] = {kInfinity, kInfinity, kInfinity};
    float hi[3] = {-kInfinity, -kInfinity, -kInfinity};
    void grow(const float* l, const float* h) {
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], l[k]);
            hi[k] = std::max(hi[k], h[k]);
        }
    }
    void grow(const Box& b) { grow(b.lo, b.hi); }
    float half_area() const {
        float dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
        if (!(dx >= 0.0f)) return 0.0f;  // empty box
        return dx * dy + dy * dz + dz * dx;
    }
};

float half_area(float3 lo, float3 hi) {
    float3 d = hi - lo;
    if (!(d.x >= 0.0f)) return 0.0f;
    return d.x * d.y + d.y * d.z + d.z * d.x;
}

/// A bin's box as two SIMD registers (x, y, z, unused), when SSE is there.
struct BinBox {
#if defined(__SSE2__)
    __m128 lo, hi;
    void clear() {
        lo = _mm_set1_ps(kInfinity);
        hi = _mm_set1_ps(-kInfinity);
    }
    void grow(__m128 l, __m128 h) {
        lo = _mm_min_ps(lo, l);
        hi = _mm_max_ps(hi, h);
    }
    void grow(const BinBox& b) {
        grow(b.lo, b.hi);
    }
    float half_area() const {
        alignas(16) float d[4];
        _mm_store_ps(d, _mm_sub_ps(hi, lo));
        if (!(d[0] >= 0.0f)) return 0.0f;
        return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
    }
#else
    Box box;
    void clear() {
        box = Box{};
    }
    void grow(const BinBox& b) {
        box.grow(b.box);
    }
    float half_area() const {
        return box.half_area();
    }
#endif
};

/// Shared state of one build; node slots are handed out by an atomic counter so that
/// subtrees can be built on several threads (children always follow their parent).
struct Builder {
    std::vector<BvhNode>& nodes;
    std::vector<PrimRef>& refs;
    BuildOptions opt;
    std::atomic<uint32_t> next_node{1};
    std::atomic<unsigned> max_depth{0};
    unsigned spawn_depth = 0;  // subtrees above this depth may go to a new thread
    unsigned block_shift = 0;  // leaf work counted in blocks of 1 << block_shift prims

    uint32_t blocks(uint32_t n) const { return (n + (1u << block_shift) - 1) >> block_shift; }

    Builder(std::vector<BvhNode>& n, std::vector<PrimRef>& r, const BuildOptions& o)
        : nodes(n), refs(r), opt(o) {}

    /// Bins refs[begin, end) along all three axes at once (Wald 2007, Sec. 3.2).
    void bin_prims(uint32_t begin, uint32_t end, const Box& cb, const float* scale, int bins,
                   BinBox (*bin_box)[kMaxBins], uint32_t (*bin_count)[kMaxBins]) const {
#if defined(__SSE2__)
        const __m128 origin = _mm_setr_ps(cb.lo[0], cb.lo[1], cb.lo[2], 0.0f);
        const __m128 s = _mm_setr_ps(scale[0], scale[1], scale[2], 0.0f);
        const __m128i last = _mm_set1_epi32(bins - 1);
        const __m128 xyz_mask = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
        alignas(16) int32_t b[4];
        for (uint32_t i = begin; i < end; ++i) {
            const PrimRef& r = refs[i];
            // Lane 3 holds the id bits, which may read as a denormal: clear it, denormal
            // arithmetic is a slow microcode path.
            const __m128 lo = _mm_and_ps(_mm_loadu_ps(r.lo), xyz_mask);
            const __m128 hi = _mm_and_ps(_mm_loadu_ps(r.hi), xyz_mask);
            __m128i bi = _mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(_mm_add_ps(lo, hi), origin), s));
#if defined(__SSE4_1__)
            bi = _mm_max_epi32(_mm_min_epi32(bi, last), _mm_setzero_si128());
            _mm_store_si128((__m128i*)b, bi);
#else
            _mm_store_si128((__m128i*)b, bi);
            for (int k = 0; k < 3; ++k) b[k] = std::clamp(b[k], 0, bins - 1);
#endif
            for (int k = 0; k < 3; ++k) {
                bin_box[k][b[k]].grow(lo, hi);
                bin_count[k][b[k]]++;
            }
        }
#else
        for (uint32_t i = begin; i < end; ++i) {
            const PrimRef& r = refs[i];
            for (int k = 0; k < 3; ++k) {
                int b = std::clamp((int)((r.lo[k] + r.hi[k] - cb.lo[k]) * scale[k]), 0, bins - 1);
                bin_box[k][b].box.grow(r.lo, r.hi);
                bin_count[k][b]++;
            }
        }
#endif
    }

    /// The bin of a ref along axis k: the same arithmetic as bin_prims, lane k.
    static int bin_of(const PrimRef& r, int k, const Box& cb, const float* scale, int bins) {
        return std::clamp((int)((r.lo[k] + r.hi[k] - cb.lo[k]) * scale[k]), 0, bins - 1);
    }

    void make_leaf(uint32_t node, uint32_t begin, uint32_t end) {
        nodes[node].first = begin;
        nodes[node].count = end - begin;
    }

    /// Builds the subtree of `node` over refs[begin, end) whose centroids lie in cb
    /// (centroids are stored doubled, lo + hi, to save a multiply per primitive).
    void build(uint32_t node, uint32_t begin, uint32_t end, unsigned depth, Box cb) {
        unsigned seen = max_depth.load(std::memory_order_relaxed);
        while (depth > seen && !max_depth.compare_exchange_weak(seen, depth)) {
        }
        const uint32_t n = end - begin;
        const uint32_t max_leaf = std::max(1, opt.max_leaf_size);
        if (n <= 1) return make_leaf(node, begin, end);

        // Depth guard: below this depth a median split can still finish within kMaxDepth.
        const unsigned levels_needed = std::bit_width((n + max_leaf - 1) / max_leaf);
        const bool force_median = depth + levels_needed + 1 >= kMaxDepth;

        int best_axis = -1, best_bin = 0;
        float best_cost = kInfinity;
        float scale[3] = {0.0f, 0.0f, 0.0f};
        // Small nodes get fewer bins: clearing and sweeping 32 bins would dominate them.
        const int bins = std::clamp(std::min(opt.bins, (int)n + 4), 2, kMaxBins);
        if (!force_median) {
            for (int k = 0; k < 3; ++k) {
                float extent = cb.hi[k] - cb.lo[k];
                scale[k] = extent > 0.0f ? bins * 0.99999f / extent : 0.0f;
            }
            BinBox bin_box[3][kMaxBins];
            uint32_t bin_count[3][kMaxBins];
            for (int k = 0; k < 3; ++k)
                for (int b = 0; b < bins; ++b) {
                    bin_box[k][b].clear();
                    bin_count[k][b] = 0;
                }
            bin_prims(begin, end, cb, scale, bins, bin_box, bin_count);
            // Sweep: right-to-left areas and counts, then the cost of each plane.
            for (int k = 0; k < 3; ++k) {
                if (scale[k] == 0.0f) continue;
                float right_area[kMaxBins];
                uint32_t right_count[kMaxBins];
                BinBox acc;
                acc.clear();
                uint32_t cnt = 0;
                for (int b = bins - 1; b > 0; --b) {
                    acc.grow(bin_box[k][b]);
                    cnt += bin_count[k][b];
                    right_area[b] = acc.half_area();
                    right_count[b] = cnt;
                }
                BinBox left;
                left.clear();
                uint32_t left_count = 0;
                for (int b = 1; b < bins; ++b) {
                    left.grow(bin_box[k][b - 1]);
                    left_count += bin_count[k][b - 1];
                    if (left_count == 0 || right_count[b] == 0) continue;
                    float cost = left.half_area() * blocks(left_count) +
                                 right_area[b] * blocks(right_count[b]);
                    if (cost < best_cost) {
                        best_cost = cost;
                        best_axis = k;
                        best_bin = b;
                    }
                }
            }
        }

        const BvhNode& self = nodes[node];
        const float area = half_area(self.lo, self.hi);
        if (best_axis >= 0 && n <= max_leaf) {
            // SAH termination: a leaf when testing its primitives is no dearer than a split.
            float split = opt.traversal_cost + opt.intersection_cost * best_cost / area;
            if (!(area > 0.0f) || opt.intersection_cost * blocks(n) <= split)
                return make_leaf(node, begin, end);
        }
        if (best_axis < 0 && n <= max_leaf) return make_leaf(node, begin, end);

        uint32_t mid;
        if (best_axis >= 0) {
            const int k = best_axis;
            auto it = std::partition(
                refs.begin() + begin, refs.begin() + end,
                [&](const PrimRef& r) { return bin_of(r, k, cb, scale, bins) < best_bin; });
            mid = (uint32_t)(it - refs.begin());
        } else {
            // All centroids coincide (or the depth guard): split the range in half.
            mid = begin + n / 2;
        }

        // Child boxes and centroid boxes.
        Box box[2], cbox[2];
        for (uint32_t i = begin; i < end; ++i) {
            const PrimRef& r = refs[i];
            int side = i < mid ? 0 : 1;
            box[side].grow(r.lo, r.hi);
            float c[3] = {r.lo[0] + r.hi[0], r.lo[1] + r.hi[1], r.lo[2] + r.hi[2]};
            cbox[side].grow(c, c);
        }
        const uint32_t left = next_node.fetch_add(2);
        for (int s = 0; s < 2; ++s) {
            BvhNode& c = nodes[left + s];
            c.lo = make_float3(box[s].lo[0], box[s].lo[1], box[s].lo[2]);
            c.hi = make_float3(box[s].hi[0], box[s].hi[1], box[s].hi[2]);
            c.count = 0;
        }
        nodes[node].first = left;
        nodes[node].count = 0;
        if (depth < spawn_depth && n > 8192) {
            std::thread worker([&, left, begin, mid, depth, c0 = cbox[0]] {
                build(left, begin, mid, depth + 1, c0);
            });
            build(left + 1, mid, end, depth + 1, cbox[1]);
            worker.join();
        } else {
            build(left, begin, mid, depth + 1, cbox[0]);
            build(left + 1, mid, end, depth + 1, cbox[1]);
        }
    }
};

}  // namespace

void Bvh::build(std::span<const Aabb> boxes, const BuildOptions& options, BuildStats* stats) {
    auto start = std::chrono::steady_clock::now();
    m_nodes.clear();
    m_prim_order.clear();
    if (boxes.empty()) {
        if (stats) *stats = BuildStats{};
        return;
    }
    const size_t n = boxes.size();
    std::vector<PrimRef> refs(n);
    Box root, cb;
    for (size_t i = 0; i < n; ++i) {
        PrimRef& r = refs[i];
        r.lo[0] = boxes[i].lo.x, r.lo[1] = boxes[i].lo.y, r.lo[2] = boxes[i].lo.z;
        r.hi[0] = boxes[i].hi.x, r.hi[1] = boxes[i].hi.y, r.hi[2] = boxes[i].hi.z;
        r.id = (uint32_t)i;
        r.pad = 0.0f;
        root.grow(r.lo, r.hi);
        float c[3] = {r.lo[0] + r.hi[0], r.lo[1] + r.hi[1], r.lo[2] + r.hi[2]};
        cb.grow(c, c);
    }
    m_nodes.resize(2 * n);
    m_nodes[0].lo = make_float3(root.lo[0], root.lo[1], root.lo[2]);
    m_nodes[0].hi = make_float3(root.hi[0], root.hi[1], root.hi[2]);
    Builder builder(m_nodes, refs, options);
    unsigned threads = std::max(1u, std::thread::hardware_concurrency());
    builder.spawn_depth = std::bit_width(threads) - 1;
    builder.block_shift = std::bit_width(std::max(1u, m_block_size)) - 1;
    builder.build(0, 0, (uint32_t)n, 0, cb);
    m_nodes.resize(builder.next_node.load());
    m_prim_order.resize(n);
    for (size_t i = 0; i < n; ++i) m_prim_order[i] = refs[i].id;

    if (stats) {
        stats->build_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        stats->sah_cost = sah_cost(options);
        stats->node_count = m_nodes.size();
        stats->leaf_count = 0;
        for (const BvhNode& node : m_nodes) stats->leaf_count += node.count > 0;
        stats->depth = builder.max_depth.load();
    }
}

void Bvh::refit(std::span<const Aabb> boxes) {
    // Children always have larger indices than their parent, so one backward pass works.
    for (size_t i = m_nodes.size(); i-- > 0;) {
        BvhNode& node = m_nodes[i];
        float3 lo = make_float3(kInfinity), hi = make_float3(-kInfinity);
        if (node.count > 0) {
            for (uint32_t j = 0; j < node.count; ++j) {
                const Aabb& b = boxes[m_prim_order[node.first + j]];
                lo = fminf(lo, b.lo);
                hi = fmaxf(hi, b.hi);
            }
        } else {
            const BvhNode& a = m_nodes[node.first];
            const BvhNode& b = m_nodes[node.first + 1];
            lo = fminf(a.lo, b.lo);
            hi = fmaxf(a.hi, b.hi);
        }
        node.lo = lo;
        node.hi = hi;
    }
}

Aabb Bvh::bounds() const {
    if (m_nodes.empty()) return Aabb{make_float3(kInfinity), make_float3(-kInfinity)};
    return Aabb{m_nodes[0].lo, m_nodes[0].hi};
}

double Bvh::sah_cost(const BuildOptions& options) const {
    if (m_nodes.empty()) return 0.0;
    const double root = half_area(m_nodes[0].lo, m_nodes[0].hi);
    double cost = 0.0;
    for (const BvhNode& node : m_nodes) {
        double a = half_area(node.lo, node.hi);
        cost += node.count > 0 ? options.intersection_cost * node.count * a
                               : options.traversal_cost * a;
    }
    return root > 0.0 ? cost / root : cost;
}

}  // namespace lucent::accel

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
// Spatial splits are tried where the best object split's children overlap by more than this
// share of the root's area. Stich et al. suggest 1e-5; on Sponza and Sibenik 1e-3 kept the
// rays as fast (diffuse +25 % / +8 % over no splits) for 55 ms of build instead of 125.
constexpr float kSpatialSplitOverlap = 1e-3f;

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

    // Spatial splits (Stich et al. 2009): tried where the best object split's two boxes
    // overlap by more than min_overlap (kSpatialSplitOverlap of the root's area).
    const SplitTriangles* split = nullptr;
    float min_overlap = 0.0f;

    float3 vertex(uint32_t prim, int v) const {
        const uint32_t index = split->indices.empty() ? 3 * prim + uint32_t(v)
                                                      : (v == 0   ? split->indices[prim].x
                                                         : v == 1 ? split->indices[prim].y
                                                                  : split->indices[prim].z);
        return split->vertices[index];
    }

    /// The box of the part of triangle r.id between lo and hi along `axis`, within r's box
    /// (Sutherland-Hodgman clipping against the two planes; empty when nothing is left).
    Box clipped(const PrimRef& r, int axis, float lo, float hi) const {
        float pts[2][8][3];
        int n = 3;
        for (int v = 0; v < 3; ++v) {
            const float3 p = vertex(r.id, v);
            pts[0][v][0] = p.x, pts[0][v][1] = p.y, pts[0][v][2] = p.z;
        }
        int from = 0;
        for (int side = 0; side < 2; ++side) {
            const float plane = side == 0 ? lo : hi;
            auto inside = [&](const float* q) {
                return side == 0 ? q[axis] >= plane : q[axis] <= plane;
            };
            int m = 0;
            for (int i = 0; i < n; ++i) {
                const float* a = pts[from][i];
                const float* b = pts[from][(i + 1) % n];
                if (inside(a)) std::copy(a, a + 3, pts[1 - from][m++]);
                if (inside(a) != inside(b)) {
                    const float t = (plane - a[axis]) / (b[axis] - a[axis]);
                    float* q = pts[1 - from][m++];
                    for (int k = 0; k < 3; ++k) q[k] = a[k] + t * (b[k] - a[k]);
                    q[axis] = plane;
                }
            }
            n = m;
            from = 1 - from;
        }
        Box box;
        for (int i = 0; i < n; ++i) box.grow(pts[from][i], pts[from][i]);
        for (int k = 0; k < 3; ++k) {
            box.lo[k] = std::max(box.lo[k], r.lo[k]);
            box.hi[k] = std::min(box.hi[k], r.hi[k]);
        }
        return box;
    }

    static bool empty(const Box& b) {
        return !(b.lo[0] <= b.hi[0] && b.lo[1] <= b.hi[1] && b.lo[2] <= b.hi[2]);
    }

    struct SpatialSplit {
        int axis = -1;
        float position = 0.0f;
        float cost = kInfinity;
        Box left, right;  // the two sides' boxes and reference counts, for unsplitting
        uint32_t left_count = 0, right_count = 0;
    };

    /// The best spatial split of refs[begin, end) within `bounds`: 16 bins, a
    /// reference counted where it enters and where it leaves, its clipped part in each bin.
    SpatialSplit find_spatial_split(uint32_t begin, uint32_t end, const BvhNode& bounds) const {
        constexpr int kBins = 16;
        SpatialSplit best;
        const float lo3[3] = {bounds.lo.x, bounds.lo.y, bounds.lo.z};
        const float hi3[3] = {bounds.hi.x, bounds.hi.y, bounds.hi.z};
        // Along the longest axis only: the other two cost twice the build time and, over
        // four interleaved A/B rounds on Sponza and Sibenik, bought no measurable speed.
        int k = 0;
        for (int j = 1; j < 3; ++j)
            if (hi3[j] - lo3[j] > hi3[k] - lo3[k]) k = j;
        const float extent = hi3[k] - lo3[k];
        if (!(extent > 0.0f)) return best;
        const float width = extent / kBins, inv = kBins / extent;
        Box box[kBins];
        uint32_t enter[kBins] = {}, leave[kBins] = {};
        for (uint32_t i = begin; i < end; ++i) {
            const PrimRef& r = refs[i];
            const int b0 = std::clamp(int((r.lo[k] - lo3[k]) * inv), 0, kBins - 1);
            const int b1 = std::clamp(int((r.hi[k] - lo3[k]) * inv), b0, kBins - 1);
            ++enter[b0];
            ++leave[b1];
            if (b0 == b1) {
                box[b0].grow(r.lo, r.hi);
                continue;
            }
            for (int b = b0; b <= b1; ++b) {
                const float bl = b == 0 ? -kInfinity : lo3[k] + b * width;
                const float bh = b == kBins - 1 ? kInfinity : lo3[k] + (b + 1) * width;
                const Box part = clipped(r, k, bl, bh);
                if (!empty(part)) box[b].grow(part);
            }
        }
        float right_area[kBins];
        uint32_t right_count[kBins];
        Box acc;
        uint32_t count = 0;
        for (int b = kBins - 1; b > 0; --b) {
            acc.grow(box[b]);
            count += leave[b];
            right_area[b] = acc.half_area();
            right_count[b] = count;
        }
        Box left;
        uint32_t left_count = 0;
        for (int b = 1; b < kBins; ++b) {
            left.grow(box[b - 1]);
            left_count += enter[b - 1];
            if (left_count == 0 || right_count[b] == 0) continue;
            const float cost =
                left.half_area() * blocks(left_count) + right_area[b] * blocks(right_count[b]);
            if (cost < best.cost) {
                best.axis = k, best.position = lo3[k] + b * width, best.cost = cost;
                best.left = left;
                best.right = Box{};
                for (int c = b; c < kBins; ++c) best.right.grow(box[c]);
                best.left_count = left_count, best.right_count = right_count[b];
            }
        }
        return best;
    }

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
    /// refs[end, ext_end) is free room for the references spatial splits duplicate.
    void build(uint32_t node, uint32_t begin, uint32_t end, uint32_t ext_end, unsigned depth,
               Box cb) {
        unsigned seen = max_depth.load(std::memory_order_relaxed);
        while (depth > seen && !max_depth.compare_exchange_weak(seen, depth)) {
        }
        const uint32_t n = end - begin;
        const uint32_t max_leaf = opt.max_leaf_size > 0 ? uint32_t(opt.max_leaf_size) : 4u;
        if (n <= 1) return make_leaf(node, begin, end);

        // Depth guard: below this depth a median split can still finish within kMaxDepth.
        const unsigned levels_needed = std::bit_width((n + max_leaf - 1) / max_leaf);
        const bool force_median = depth + levels_needed + 1 >= kMaxDepth;

        int best_axis = -1, best_bin = 0;
        float best_cost = kInfinity;
        float scale[3] = {0.0f, 0.0f, 0.0f};
        // Small nodes get fewer bins: clearing and sweeping 32 bins would dominate them.
        const int bins = std::clamp(std::min(opt.bins, (int)n + 4), 2, kMaxBins);
        float overlap = 0.0f;  // of the best object split's two boxes (spatial splits only)
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
            if (split && best_axis >= 0)
                overlap = object_overlap(best_axis, best_bin, bins, bin_box);
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

        if (split && n > max_leaf && !force_median && ext_end > end && best_axis >= 0 &&
            overlap > min_overlap) {
            const SpatialSplit s = find_spatial_split(begin, end, self);
            if (s.axis >= 0 && s.cost < best_cost &&
                split_space(node, begin, end, ext_end, depth, s))
                return;
        }

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
        // The free room goes to the children in proportion to their references.
        const uint32_t room = ext_end - end;
        const uint32_t left_room = uint32_t(uint64_t(room) * (mid - begin) / n);
        if (left_room > 0)
            std::move_backward(refs.begin() + mid, refs.begin() + end,
                               refs.begin() + end + left_room);
        children(node, begin, mid, mid + left_room, mid + left_room, end + left_room, ext_end,
                 depth, box, cbox);
    }

    /// Makes node's two children over refs[b0, e0) (room up to x0) and refs[b1, e1) (room up
    /// to x1), and builds them, the first on another thread near the root of big trees.
    void children(uint32_t node, uint32_t b0, uint32_t e0, uint32_t x0, uint32_t b1, uint32_t e1,
                  uint32_t x1, unsigned depth, const Box* box, const Box* cbox) {
        const uint32_t left = next_node.fetch_add(2);
        for (int s = 0; s < 2; ++s) {
            BvhNode& c = nodes[left + s];
            c.lo = make_float3(box[s].lo[0], box[s].lo[1], box[s].lo[2]);
            c.hi = make_float3(box[s].hi[0], box[s].hi[1], box[s].hi[2]);
            c.count = 0;
        }
        nodes[node].first = left;
        nodes[node].count = 0;
        if (depth < spawn_depth && e1 - b0 > 8192) {
            std::thread worker([&, left, b0, e0, x0, depth, c0 = cbox[0]] {
                build(left, b0, e0, x0, depth + 1, c0);
            });
            build(left + 1, b1, e1, x1, depth + 1, cbox[1]);
            worker.join();
        } else {
            build(left, b0, e0, x0, depth + 1, cbox[0]);
            build(left + 1, b1, e1, x1, depth + 1, cbox[1]);
        }
    }

    /// Area of the overlap of the best object split's two boxes.
    static float object_overlap(int axis, int split_bin, int bins, BinBox (*bin_box)[kMaxBins]) {
        BinBox l, r;
        l.clear();
        r.clear();
        for (int b = 0; b < bins; ++b) (b < split_bin ? l : r).grow(bin_box[axis][b]);
        Box lb = to_box(l), rb = to_box(r);
        for (int k = 0; k < 3; ++k) {
            lb.lo[k] = std::max(lb.lo[k], rb.lo[k]);
            lb.hi[k] = std::min(lb.hi[k], rb.hi[k]);
        }
        return empty(lb) ? 0.0f : lb.half_area();
    }

    static Box to_box(const BinBox& b) {
        Box out;
#if defined(__SSE2__)
        alignas(16) float lo[4], hi[4];
        _mm_store_ps(lo, b.lo);
        _mm_store_ps(hi, b.hi);
        std::copy(lo, lo + 3, out.lo);
        std::copy(hi, hi + 3, out.hi);
#else
        out = b.box;
#endif
        return out;
    }

    /// Reference unsplitting (Stich et al. 2009, Sec. 4.4): 0 or 1 when putting the whole of
    /// a straddling reference on that side costs less than splitting it, else -1. Updates
    /// the split's boxes and counts to what it chose.
    int unsplit(const PrimRef& r, SpatialSplit& s) const {
        Box left = s.left, right = s.right;
        left.grow(r.lo, r.hi);
        right.grow(r.lo, r.hi);
        const float al = s.left.half_area(), ar = s.right.half_area();
        const float nl = float(s.left_count), nr = float(s.right_count);
        const float c_split = al * nl + ar * nr;
        const float c_left = left.half_area() * nl + ar * (nr - 1.0f);
        const float c_right = al * (nl - 1.0f) + right.half_area() * nr;
        if (c_left < c_split && c_left <= c_right) {
            s.left = left, --s.right_count;
            return 0;
        }
        if (c_right < c_split) {
            s.right = right, --s.left_count;
            return 1;
        }
        return -1;
    }

    /// Splits refs[begin, end) at `s`: references across the plane are clipped into both
    /// sides. False (and nothing changed) when a side would be empty or the room is short.
    bool split_space(uint32_t node, uint32_t begin, uint32_t end, uint32_t ext_end, unsigned depth,
                     SpatialSplit s) {
        std::vector<PrimRef> left, right;
        left.reserve(end - begin);
        right.reserve(end - begin);
        for (uint32_t i = begin; i < end; ++i) {
            const PrimRef& r = refs[i];
            if (r.hi[s.axis] <= s.position) {
                left.push_back(r);
            } else if (r.lo[s.axis] >= s.position) {
                right.push_back(r);
            } else if (const int side = unsplit(r, s); side >= 0) {
                (side == 0 ? left : right).push_back(r);  // whole, on the cheaper side
            } else {
                for (int side = 0; side < 2; ++side) {
                    const Box part = side == 0 ? clipped(r, s.axis, -kInfinity, s.position)
                                               : clipped(r, s.axis, s.position, kInfinity);
                    if (empty(part)) continue;
                    PrimRef c = r;
                    std::copy(part.lo, part.lo + 3, c.lo);
                    std::copy(part.hi, part.hi + 3, c.hi);
                    (side == 0 ? left : right).push_back(c);
                }
            }
        }
        const uint64_t used = left.size() + right.size();
        if (left.empty() || right.empty() || used > ext_end - begin || left.size() == end - begin ||
            right.size() == end - begin)
            return false;
        const uint32_t room = uint32_t(ext_end - begin - used);
        const uint32_t left_room = uint32_t(uint64_t(room) * left.size() / used);
        const uint32_t b1 = begin + uint32_t(left.size()) + left_room;
        std::copy(left.begin(), left.end(), refs.begin() + begin);
        std::copy(right.begin(), right.end(), refs.begin() + b1);
        Box box[2], cbox[2];
        for (int side = 0; side < 2; ++side)
            for (const PrimRef& r : side == 0 ? left : right) {
                box[side].grow(r.lo, r.hi);
                float c[3] = {r.lo[0] + r.hi[0], r.lo[1] + r.hi[1], r.lo[2] + r.hi[2]};
                cbox[side].grow(c, c);
            }
        children(node, begin, begin + uint32_t(left.size()), b1, b1, b1 + uint32_t(right.size()),
                 ext_end, depth, box, cbox);
        return true;
    }
};

}  // namespace

void Bvh::build(std::span<const Aabb> boxes, const BuildOptions& options, BuildStats* stats,
                const SplitTriangles* split) {
    auto start = std::chrono::steady_clock::now();
    m_nodes.clear();
    m_prim_order.clear();
    if (boxes.empty()) {
        if (stats) *stats = BuildStats{};
        return;
    }
    const size_t n = boxes.size();
    // Room for the references spatial splits add; unused slots stay empty and unreferenced.
    const size_t capacity = split ? n + size_t(double(n) * std::max(0.0f, split->budget)) : n;
    std::vector<PrimRef> refs(
        capacity,
        PrimRef{{kInfinity, kInfinity, kInfinity}, 0, {-kInfinity, -kInfinity, -kInfinity}, 0.0f});
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
    m_nodes.resize(2 * capacity);
    m_nodes[0].lo = make_float3(root.lo[0], root.lo[1], root.lo[2]);
    m_nodes[0].hi = make_float3(root.hi[0], root.hi[1], root.hi[2]);
    Builder builder(m_nodes, refs, options);
    const unsigned threads =
        options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
    builder.spawn_depth = std::bit_width(threads) - 1;
    builder.block_shift = std::bit_width(std::max(1u, m_block_size)) - 1;
    if (split) {
        builder.split = split;
        builder.min_overlap = kSpatialSplitOverlap * root.half_area();
    }
    builder.build(0, 0, (uint32_t)n, (uint32_t)capacity, 0, cb);
    m_nodes.resize(builder.next_node.load());
    m_prim_order.resize(capacity);
    for (size_t i = 0; i < capacity; ++i) m_prim_order[i] = refs[i].id;

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

// Ray-stream traversal of TriangleAccel's 8-wide tree (ray_stream.h): closest hit and
// occlusion for a batch of rays, node by node. Compiled once per instruction-set variant
// beside triangle_traverse.cpp (cmake/isa_variants.cmake); the AVX-512 variant runs the
// stream, sixteen rays to an instruction, and the others trace the batch's rays one by one
// with their single-ray loop, so every variant gives the same answers. An eight-lane AVX2
// stream (AVX2's gathers, a permutation table for the compress, the scatters one lane at a
// time) was measured in session 37 and lost to the AVX2 single-ray loop on primary and
// shadow rays and tied it on diffuse rays (docs/performance.md, Session 37).
//
// The answers equal the single-ray queries': the same watertight test with the same
// arithmetic gives the same t, u and v for a triangle. Only which of two triangles hit at
// exactly the same t is reported may differ, as the triangles are met in another order.
#include <bit>
#include <cmath>

#include "accel/inverse_direction.h"
#include "accel/ray_stream.h"
#include "accel/triangle_accel.h"
#include "accel/triangle_traverse.h"
#include "accel/wide_bvh.h"
#include "lucent/device/triangle_intersect.h"

#if defined(__AVX512F__) && defined(__AVX512DQ__) && defined(__FMA__) && \
    !defined(LUCENT_ACCEL_SCALAR)
#include <immintrin.h>
#define LUCENT_STREAM_SIMD 1
// GCC 12's AVX-512 intrinsics pass an undefined vector as the unused source of their masked
// forms, which -Wmaybe-uninitialized reports at every use (GCC bug 105593, fixed in 13).
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ < 13
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#else
#define LUCENT_STREAM_SIMD 0
#endif

#ifndef LUCENT_ISA_VARIANT
#error "compiled only through cmake/isa_variants.cmake, which names the variant"
#endif

namespace lucent::accel::LUCENT_ISA_VARIANT {

// The variant's single-ray queries (triangle_traverse.cpp).
bool intersect(const TriangleAccel::Impl& accel, float3 origin, float3 direction, float tmin,
               float tmax, TriangleHit& hit);
bool occluded(const TriangleAccel::Impl& accel, float3 origin, float3 direction, float tmin,
              float tmax);

namespace {

enum class StreamQuery { kClosest, kAny };

#if LUCENT_STREAM_SIMD

// The slab distances here are (plane - o) * (1/d): three roundings, so a computed distance
// is within a factor (1 +- gamma(3)) of the true one. Scaling the far distance by
// 1 + 2 gamma(3) keeps every box the ray touches (Ize 2013, "Robust BVH ray traversal";
// pbrt's Bounds3::IntersectP); 1 + 2^-21 = 1 + 8u is more than 1 + 6u.
constexpr float kFarScale = 1.0f + 0x1p-21f;
constexpr int kRecordFloats = sizeof(StreamNodeRay) / sizeof(float);
static_assert(kRecordFloats == 8 && sizeof(StreamLeafRay) == sizeof(StreamNodeRay));

/// The batch's records: what the node test and the triangle test read of each ray. The
/// divisions go three to an instruction, as in the single-ray test's set-up (the same
/// correctly rounded quotients as one at a time): one at a time they were a sixth of a
/// diffuse stream's time.
void set_up_rays(const StreamRay* rays, uint32_t count, StreamBuffers& b) {
    const __m128 one = _mm_set1_ps(1.0f);
    const __m128 sign_bit = _mm_set1_ps(-0.0f);
    for (uint32_t i = 0; i < count; ++i) {
        const StreamRay& ray = rays[i];
        const __m128 o = _mm_setr_ps(ray.origin.x, ray.origin.y, ray.origin.z, 0.0f);
        const __m128 d = _mm_setr_ps(ray.direction.x, ray.direction.y, ray.direction.z, 1.0f);
        const __m128 limit = _mm_min_ps(
            _mm_set1_ps(kMaxInverse),
            _mm_div_ps(_mm_set1_ps(kMaxOverInverse), _mm_max_ps(_mm_andnot_ps(sign_bit, o), one)));
        const __m128 inverse =
            _mm_max_ps(_mm_min_ps(_mm_div_ps(one, d), limit), _mm_xor_ps(limit, sign_bit));
        float* node = reinterpret_cast<float*>(&b.node_rays[i]);
        _mm_store_ps(node, _mm_insert_ps(o, _mm_set_ss(ray.tmax), 0x30));
        _mm_store_ps(node + 4, _mm_insert_ps(inverse, _mm_set_ss(ray.tmin), 0x30));

        const WatertightAxes a = watertight_axes(ray.direction);
        const float org[3] = {ray.origin.x, ray.origin.y, ray.origin.z};
        const float dir[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
        alignas(16) float shear[4];
        _mm_store_ps(shear, _mm_div_ps(_mm_setr_ps(dir[a.kx], dir[a.ky], 1.0f, 0.0f),
                                       _mm_set1_ps(dir[a.kz])));
        b.leaf_rays[i] = StreamLeafRay{org[a.kx], org[a.ky], org[a.kz], a.kx | a.ky << 2 | a.kz << 4,
                                       shear[0],  shear[1],  shear[2],  0.0f};
        b.prim[i] = kStreamMiss;
    }
}

/// The lanes of a group of sixteen stream entries starting at i that hold rays.
inline __mmask16 valid_lanes(uint32_t i, uint32_t count) {
    return count - i >= 16 ? __mmask16(0xffff) : __mmask16((1u << (count - i)) - 1);
}

/// Field `field` of sixteen rays' records (the index vector is the ray index times 8).
template <class Record>
inline __m512 gather(const Record* records, int field, __m512i record_index, __mmask16 valid) {
    return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), valid, record_index,
                                    reinterpret_cast<const float*>(records) + field, 4);
}

/// Tests the `count` rays of `ids` against the node's children. The rays that hit child c
/// are written, in stream order, to out + c * capacity and counted in size[c]; negative[k]
/// counts the rays whose direction is negative on axis k, for the children's order.
void test_node_stream(const WideNode& node, const uint32_t* ids, uint32_t count,
                      const StreamNodeRay* records, uint32_t* out, uint32_t capacity,
                      uint32_t size[kWideArity], uint32_t negative[3]) {
    int children[kWideArity], child_count = 0;
    for (int c = 0; c < kWideArity; ++c) {
        size[c] = 0;
        if (node.child[c] != kEmptyChild) children[child_count++] = c;
    }
    const __m512 far_scale = _mm512_set1_ps(kFarScale);
    negative[0] = negative[1] = negative[2] = 0;
    for (uint32_t i = 0; i < count; i += 16) {
        const __mmask16 valid = valid_lanes(i, count);
        const __m512i id = _mm512_maskz_loadu_epi32(valid, ids + i);
        const __m512i record = _mm512_slli_epi32(id, 3);
        const __m512 o[3] = {gather(records, 0, record, valid), gather(records, 1, record, valid),
                             gather(records, 2, record, valid)};
        const __m512 inverse[3] = {gather(records, 4, record, valid),
                                   gather(records, 5, record, valid),
                                   gather(records, 6, record, valid)};
        const __m512 t_end = _mm512_mul_ps(gather(records, 3, record, valid), far_scale);
        const __m512 t_start = gather(records, 7, record, valid);
        for (int k = 0; k < 3; ++k)
            negative[k] += (unsigned)std::popcount(
                unsigned(_mm512_movepi32_mask(_mm512_castps_si512(inverse[k])) & valid));
        for (int j = 0; j < child_count; ++j) {
            const int c = children[j];
            __m512 t_near = t_start, t_far = _mm512_set1_ps(HUGE_VALF);
            for (int k = 0; k < 3; ++k) {
                const __m512 t0 = _mm512_mul_ps(
                    _mm512_sub_ps(_mm512_set1_ps(node.planes[k][0][c]), o[k]), inverse[k]);
                const __m512 t1 = _mm512_mul_ps(
                    _mm512_sub_ps(_mm512_set1_ps(node.planes[k][1][c]), o[k]), inverse[k]);
                t_near = _mm512_max_ps(t_near, _mm512_min_ps(t0, t1));
                t_far = _mm512_min_ps(t_far, _mm512_max_ps(t0, t1));
            }
            const __mmask16 hit = _mm512_mask_cmp_ps_mask(
                valid, t_near, _mm512_min_ps(_mm512_mul_ps(t_far, far_scale), t_end), _CMP_LE_OQ);
            // Compressed in a register and stored whole (the region has sixteen slots to
            // spare): the compressing store to memory is microcoded and slow on some CPUs.
            _mm512_storeu_si512(out + c * capacity + size[c], _mm512_maskz_compress_epi32(hit, id));
            size[c] += (unsigned)std::popcount(unsigned(hit));
        }
    }
}

/// a*b - c*d on every lane, with the same operations as the single-ray test's
/// difference_of_products (and lucent/device/triangle_intersect.h's).
inline __m512 difference_of_products(__m512 a, __m512 b, __m512 c, __m512 d) {
    const __m512 cd = _mm512_mul_ps(c, d);
    const __m512 err = _mm512_fnmadd_ps(c, d, cd);
    return _mm512_add_ps(_mm512_fmsub_ps(a, b, cd), err);
}

/// Tests the `count` rays of `ids` against the triangles of a leaf, each triangle against
/// sixteen rays at once, with the single-ray test's arithmetic (test_block): the same t, and
/// the same edge functions for the barycentrics. Closest hit: a ray's record keeps its
/// nearest hit so far (tmax) and its triangle. Occlusion: a blocked ray's tmax becomes -inf,
/// which no node test or triangle passes again.
template <StreamQuery kQuery, int kLanes>
void test_leaf_stream(const TriangleBlock<kLanes>& block, uint32_t triangles, const uint32_t* ids,
                      uint32_t count, StreamBuffers& b) {
    const __m512 zero = _mm512_setzero_ps();
    const __m512i three = _mm512_set1_epi32(3);
    float* node_fields = reinterpret_cast<float*>(b.node_rays);
    for (uint32_t i = 0; i < count; i += 16) {
        const __mmask16 valid = valid_lanes(i, count);
        const __m512i id = _mm512_maskz_loadu_epi32(valid, ids + i);
        const __m512i record = _mm512_slli_epi32(id, 3);
        const __m512 ox = gather(b.leaf_rays, 0, record, valid);
        const __m512 oy = gather(b.leaf_rays, 1, record, valid);
        const __m512 oz = gather(b.leaf_rays, 2, record, valid);
        const __m512i axes = _mm512_castps_si512(gather(b.leaf_rays, 3, record, valid));
        const __m512 sx = gather(b.leaf_rays, 4, record, valid);
        const __m512 sy = gather(b.leaf_rays, 5, record, valid);
        const __m512 sz = gather(b.leaf_rays, 6, record, valid);
        const __m512 t_start = gather(b.node_rays, 7, record, valid);
        __m512 t_end = gather(b.node_rays, 3, record, valid);
        const __m512i kx = _mm512_and_si512(axes, three);
        const __m512i ky = _mm512_and_si512(_mm512_srli_epi32(axes, 2), three);
        const __m512i kz = _mm512_srli_epi32(axes, 4);
        __m512i best_prim = _mm512_setzero_si512();
        __m512 best_e1 = zero, best_e2 = zero, best_det = zero;
        __mmask16 found = 0;
        for (uint32_t j = 0; j < triangles; ++j) {
            // Vertex v's coordinates on each ray's permuted axes: lanes 0-2 hold x, y, z, and
            // each ray's kx, ky, kz pick from them.
            __m512 vertex[3][3];
            for (int v = 0; v < 3; ++v) {
                const __m512 xyz = _mm512_castps128_ps512(
                    _mm_setr_ps(block.vertex[v][0][j], block.vertex[v][1][j],
                                block.vertex[v][2][j], 0.0f));
                vertex[v][0] = _mm512_permutexvar_ps(kx, xyz);
                vertex[v][1] = _mm512_permutexvar_ps(ky, xyz);
                vertex[v][2] = _mm512_permutexvar_ps(kz, xyz);
            }
            const __m512 az = _mm512_sub_ps(vertex[0][2], oz);
            const __m512 bz = _mm512_sub_ps(vertex[1][2], oz);
            const __m512 cz = _mm512_sub_ps(vertex[2][2], oz);
            const __m512 ax = _mm512_fnmadd_ps(sx, az, _mm512_sub_ps(vertex[0][0], ox));
            const __m512 ay = _mm512_fnmadd_ps(sy, az, _mm512_sub_ps(vertex[0][1], oy));
            const __m512 bx = _mm512_fnmadd_ps(sx, bz, _mm512_sub_ps(vertex[1][0], ox));
            const __m512 by = _mm512_fnmadd_ps(sy, bz, _mm512_sub_ps(vertex[1][1], oy));
            const __m512 cx = _mm512_fnmadd_ps(sx, cz, _mm512_sub_ps(vertex[2][0], ox));
            const __m512 cy = _mm512_fnmadd_ps(sy, cz, _mm512_sub_ps(vertex[2][1], oy));
            const __m512 e0 = difference_of_products(cx, by, cy, bx);
            const __m512 e1 = difference_of_products(ax, cy, ay, cx);
            const __m512 e2 = difference_of_products(bx, ay, by, ax);
            const __mmask16 negative = _mm512_cmp_ps_mask(e0, zero, _CMP_LT_OQ) |
                                       _mm512_cmp_ps_mask(e1, zero, _CMP_LT_OQ) |
                                       _mm512_cmp_ps_mask(e2, zero, _CMP_LT_OQ);
            const __mmask16 positive = _mm512_cmp_ps_mask(e0, zero, _CMP_GT_OQ) |
                                       _mm512_cmp_ps_mask(e1, zero, _CMP_GT_OQ) |
                                       _mm512_cmp_ps_mask(e2, zero, _CMP_GT_OQ);
            const __m512 det = _mm512_add_ps(_mm512_add_ps(e0, e1), e2);
            const __mmask16 inside = valid & ~(negative & positive) &
                                     _mm512_cmp_ps_mask(det, zero, _CMP_NEQ_UQ);
            if (inside == 0) continue;
            const __m512 scaled = _mm512_fmadd_ps(
                e2, _mm512_mul_ps(sz, cz),
                _mm512_fmadd_ps(e1, _mm512_mul_ps(sz, bz),
                                _mm512_mul_ps(e0, _mm512_mul_ps(sz, az))));
            const __m512 t = _mm512_div_ps(scaled, det);
            const __mmask16 hit = inside & _mm512_cmp_ps_mask(t, t_start, _CMP_GT_OQ) &
                                  _mm512_cmp_ps_mask(t, t_end, _CMP_LT_OQ);
            if constexpr (kQuery == StreamQuery::kClosest) {
                t_end = _mm512_mask_mov_ps(t_end, hit, t);
                best_prim = _mm512_mask_mov_epi32(best_prim, hit,
                                                  _mm512_set1_epi32(int(block.prim[j])));
                best_e1 = _mm512_mask_mov_ps(best_e1, hit, e1);
                best_e2 = _mm512_mask_mov_ps(best_e2, hit, e2);
                best_det = _mm512_mask_mov_ps(best_det, hit, det);
            } else {
                t_end = _mm512_mask_mov_ps(t_end, hit, _mm512_set1_ps(-HUGE_VALF));
            }
            found |= hit;
        }
        if (found == 0) continue;
        // The sixteen rays are distinct (a stream holds a ray once), so the scatters do not
        // collide.
        _mm512_mask_i32scatter_ps(node_fields + 3, found, record, t_end, 4);
        if constexpr (kQuery == StreamQuery::kClosest) {
            _mm512_mask_i32scatter_epi32(b.prim, found, id, best_prim, 4);
            _mm512_mask_i32scatter_ps(b.e1, found, id, best_e1, 4);
            _mm512_mask_i32scatter_ps(b.e2, found, id, best_e2, 4);
            _mm512_mask_i32scatter_ps(b.det, found, id, best_det, 4);
        } else {
            _mm512_mask_i32scatter_epi32(b.prim, found, id, _mm512_setzero_si512(), 4);
        }
    }
}

/// The stream walk: a stack of nodes and leaves, each with its stream of rays. A node
/// splits its stream into its children's; for closest hits the children are pushed far to
/// near along the direction most of the stream's rays share (one order for the whole
/// stream), so that the nearer children's hits shorten the rays before the farther children
/// test them. Each child's stream lies above its parent's, in the region the parent
/// reserved, so the buffer is used as a stack of regions.
template <StreamQuery kQuery>
void traverse_stream(const TriangleAccel::Impl& accel, uint32_t count, StreamBuffers& b) {
    uint32_t* ids = b.ids;
    for (uint32_t i = 0; i < count; ++i) ids[i] = i;
    StreamEntry* stack = b.stack;
    size_t sp = 0;
    stack[sp++] = StreamEntry{0, 0, count, (count + 15) & ~15u};
    while (sp > 0) {
        const StreamEntry e = stack[--sp];
        if (e.count == 0 || e.ref == kEmptyChild) continue;
        const uint32_t* stream = ids + e.begin;
        if (is_leaf(e.ref)) {
            const uint32_t triangles = leaf_count(e.ref);
            if (is_wide_leaf(e.ref))
                test_leaf_stream<kQuery>(accel.blocks8[leaf_block(e.ref)], triangles, stream,
                                         e.count, b);
            else
                test_leaf_stream<kQuery>(accel.blocks4[leaf_block(e.ref)], triangles, stream,
                                         e.count, b);
            continue;
        }
        const WideNode& node = accel.nodes[e.ref];
        const uint32_t capacity = (e.count + 16 + 15) & ~15u;
        uint32_t size[kWideArity], negative[3];
        test_node_stream(node, stream, e.count, b.node_rays, ids + e.next_free, capacity, size,
                         negative);
        int order[kWideArity], pushed = 0;
        float key[kWideArity];
        float sign[3];
        for (int k = 0; k < 3; ++k) sign[k] = 2 * negative[k] > e.count ? -1.0f : 1.0f;
        for (int c = 0; c < kWideArity; ++c) {
            if (size[c] == 0) continue;
            // Twice the box's centre along the shared direction's signs: larger is farther.
            key[c] = 0.0f;
            for (int k = 0; k < 3; ++k)
                key[c] += sign[k] * (node.planes[k][0][c] + node.planes[k][1][c]);
            // Insertion by key, farthest first (a library sort would be a template instance
            // outside the variant's namespace; cmake/check_isa_symbols.cmake).
            int j = pushed++;
            for (; j > 0 && (kQuery == StreamQuery::kClosest && key[order[j - 1]] < key[c]); --j)
                order[j] = order[j - 1];
            order[j] = c;
        }
        const uint32_t next_free = e.next_free + kWideArity * capacity;
        for (int j = 0; j < pushed; ++j) {
            const int c = order[j];
            stack[sp++] = StreamEntry{node.child[c], e.next_free + uint32_t(c) * capacity,
                                      size[c], next_free};
        }
    }
}

#endif  // LUCENT_STREAM_SIMD

}  // namespace

void intersect_stream(const TriangleAccel::Impl& accel, const StreamRay* rays, size_t count,
                      StreamHit* hits, StreamBuffers& buffers) {
#if LUCENT_STREAM_SIMD
    set_up_rays(rays, uint32_t(count), buffers);
    traverse_stream<StreamQuery::kClosest>(accel, uint32_t(count), buffers);
    for (size_t i = 0; i < count; ++i) {
        StreamHit& h = hits[i];
        h.prim = buffers.prim[i];
        if (h.prim == kStreamMiss) continue;
        h.t = buffers.node_rays[i].tmax;
        // As the single-ray query's store_barycentrics: IEEE division, the same values.
        h.u = buffers.e1[i] / buffers.det[i];
        h.v = buffers.e2[i] / buffers.det[i];
    }
#else
    (void)buffers;
    for (size_t i = 0; i < count; ++i) {
        TriangleHit hit;
        const StreamRay& r = rays[i];
        if (intersect(accel, r.origin, r.direction, r.tmin, r.tmax, hit))
            hits[i] = StreamHit{hit.t, hit.u, hit.v, hit.prim};
        else
            hits[i].prim = kStreamMiss;
    }
#endif
}

void occluded_stream(const TriangleAccel::Impl& accel, const StreamRay* rays, size_t count,
                     uint8_t* blocked, StreamBuffers& buffers) {
#if LUCENT_STREAM_SIMD
    set_up_rays(rays, uint32_t(count), buffers);
    traverse_stream<StreamQuery::kAny>(accel, uint32_t(count), buffers);
    for (size_t i = 0; i < count; ++i) blocked[i] = buffers.prim[i] != kStreamMiss;
#else
    (void)buffers;
    for (size_t i = 0; i < count; ++i) {
        const StreamRay& r = rays[i];
        blocked[i] = occluded(accel, r.origin, r.direction, r.tmin, r.tmax);
    }
#endif
}

}  // namespace lucent::accel::LUCENT_ISA_VARIANT

// Single-ray traversal of TriangleAccel's 8-wide tree: one SIMD slab test for the eight
// children of a node (AVX2) and one watertight test for the up to eight triangles of a leaf
// (four lanes with SSE or eight with AVX, and FMA), the same arithmetic as
// lucent/device/triangle_intersect.h. Occlusion rays push children with AVX-512 where the
// flags allow it. Without AVX2/FMA (or with LUCENT_ACCEL_SCALAR) it falls back to scalar
// loops over the same layout and the same arithmetic.
//
// This file is compiled once per instruction-set variant (cmake/isa_variants.cmake): each
// copy has its own flags and puts its entry points in namespace LUCENT_ISA_VARIANT
// (isa_scalar, isa_avx2, isa_avx512), and triangle_traverse_dispatch.cpp calls the one the
// CPU runs. Everything else here has internal linkage, so the copies cannot be mixed up; the
// test accel_isa_symbols checks that no copy defines any other external symbol (an inline
// function of a header emitted with AVX-512 instructions could otherwise be picked by the
// linker for the whole program).
#include <algorithm>
#include <bit>
#include <cmath>

#include "accel/inverse_direction.h"
#include "accel/triangle_accel.h"
#include "accel/triangle_traverse.h"
#include "accel/wide_bvh.h"
#include "lucent/device/triangle_intersect.h"

#if defined(__AVX2__) && defined(__FMA__) && !defined(LUCENT_ACCEL_SCALAR)
#include <immintrin.h>
#define LUCENT_ACCEL_SIMD 1
#else
#define LUCENT_ACCEL_SIMD 0
#endif

#ifndef LUCENT_ISA_VARIANT
#error "compiled only through cmake/isa_variants.cmake, which names the variant"
#endif

namespace lucent::accel::LUCENT_ISA_VARIANT {

namespace {

/// Writes a hit's barycentrics: u = e1 / det, v = e2 / det, as one 8-byte store with SIMD.
/// The engine reads them back as one float2, and a load that spans two stores is not
/// forwarded from the store buffer (a stall on every closest hit). The packed division is
/// IEEE division per lane: the same values as the scalar one.
inline void store_barycentrics(TriangleHit& hit, float e1, float e2, float det) {
#if LUCENT_ACCEL_SIMD
    const __m128 uv = _mm_div_ps(_mm_setr_ps(e1, e2, 0.0f, 0.0f), _mm_set1_ps(det));
    _mm_storel_pi(reinterpret_cast<__m64*>(&hit.u), uv);
#else
    hit.u = e1 / det;
    hit.v = e2 / det;
#endif
}

// Far planes are tested with 1/d scaled up by 1 + 2^-21 so that rounding never culls a box
// the ray touches (Ize 2013, "Robust BVH ray traversal", scales the far distance instead).
// With u = 2^-24, a computed near distance is at most (1 + u)^2 times the true one (1/d and
// the FMA each rounded once) and a far one at least (1 - u)^3 * kFarScale times it (1/d,
// its scaling, the FMA), so near <= far survives rounding when kFarScale >= 1 + 5u + O(u^2);
// 1 + 8u leaves room. Scaling 1/d at setup keeps a multiply out of every node's test.
constexpr float kFarScale = 1.0f + 0x1p-21f;
constexpr int kStackSize = 512;  // 7 pushes per level; wide depth <= binary depth <= 60
// 1/d is clamped as inverse_direction.h says (kMaxInverse, kMaxOverInverse), as the
// streams clamp it.

/// Everything a ray needs in the inner loops, computed once per query.
struct RayState {
    int near_plane[3], far_plane[3];  // offsets into WideNode::planes[axis]
    int kx, ky, kz;                   // the watertight test's permuted axes
#if LUCENT_ACCEL_SIMD
    // The slab test in its fused form, t = plane * (1/d) - o * (1/d): one FMA per plane.
    // o * (1/d) is rounded, an absolute error the (plane - o) * (1/d) form does not have,
    // so near planes subtract o/d + err and far planes o/d - err, err bounding that
    // rounding with room to spare: the interval only widens (kFarScale covers the rest).
    // 1/d is kept finite (|1/d| <= kMaxInverse) so that o/d is.
    __m256 rdir_near8[3], rdir_far8[3], org_rdir_near8[3], org_rdir_far8[3], tmin8;
    // The watertight test's origin, shear and scale in the permuted axes (a 4-lane block
    // test takes the low half).
    __m256 ox8, oy8, oz8, sx8, sy8, sz8;

    // The setup was 7-8 % of a query's time, so its nine divisions go three to an
    // instruction (the same correctly rounded quotients as make_watertight_ray's).
    RayState(float3 o, float3 d, float t0) {
        const __m128 one = _mm_set1_ps(1.0f);
        const __m128 sign_bit = _mm_set1_ps(-0.0f);
        const __m128 o4 = _mm_setr_ps(o.x, o.y, o.z, 0.0f);
        const __m128 d4 = _mm_setr_ps(d.x, d.y, d.z, 1.0f);
        const __m128 limit = _mm_min_ps(
            _mm_set1_ps(kMaxInverse),
            _mm_div_ps(_mm_set1_ps(kMaxOverInverse), _mm_max_ps(_mm_andnot_ps(sign_bit, o4), one)));
        // 1/(+-0) is +-inf, which the clamp turns into +-limit.
        const __m128 r =
            _mm_max_ps(_mm_min_ps(_mm_div_ps(one, d4), limit), _mm_xor_ps(limit, sign_bit));
        const __m128 r_far = _mm_mul_ps(r, _mm_set1_ps(kFarScale));
        // One err serves both sides: |o/d| * 2^-21 is still several ulp of o * r_far.
        const __m128 od = _mm_mul_ps(o4, r);
        const __m128 err = _mm_mul_ps(_mm_andnot_ps(sign_bit, od), _mm_set1_ps(0x1p-21f));
        const __m128 near = _mm_add_ps(od, err);
        const __m128 far = _mm_sub_ps(_mm_mul_ps(o4, r_far), err);
        // The planes to load follow the sign of d, not of 1/d, so that the first node's
        // loads need not wait for the division (the two agree but for a NaN d).
        const unsigned negative = (unsigned)_mm_movemask_ps(d4);
        for (int k = 0; k < 3; ++k) {
            const bool neg = (negative >> k) & 1u;
            near_plane[k] = 16 * k + (neg ? 8 : 0);
            far_plane[k] = 16 * k + (neg ? 0 : 8);
            // Lane k to all eight lanes, register to register.
            const __m256i lane = _mm256_set1_epi32(k);
            rdir_near8[k] = _mm256_permutevar8x32_ps(_mm256_castps128_ps256(r), lane);
            rdir_far8[k] = _mm256_permutevar8x32_ps(_mm256_castps128_ps256(r_far), lane);
            org_rdir_near8[k] = _mm256_permutevar8x32_ps(_mm256_castps128_ps256(near), lane);
            org_rdir_far8[k] = _mm256_permutevar8x32_ps(_mm256_castps128_ps256(far), lane);
        }
        tmin8 = _mm256_set1_ps(t0);

        const float dir[3] = {d.x, d.y, d.z}, org[3] = {o.x, o.y, o.z};
        const WatertightAxes axes = watertight_axes(d);
        kx = axes.kx, ky = axes.ky, kz = axes.kz;
        alignas(16) float shear[4];
        _mm_store_ps(shear, _mm_div_ps(_mm_setr_ps(dir[axes.kx], dir[axes.ky], 1.0f, 1.0f),
                                       _mm_set1_ps(dir[axes.kz])));
        ox8 = _mm256_set1_ps(org[axes.kx]);
        oy8 = _mm256_set1_ps(org[axes.ky]);
        oz8 = _mm256_set1_ps(org[axes.kz]);
        sx8 = _mm256_set1_ps(shear[0]);
        sy8 = _mm256_set1_ps(shear[1]);
        sz8 = _mm256_set1_ps(shear[2]);
    }
#else
    // The same fused slab test and watertight setup in scalar code, bit for bit.
    float rdir_near[3], rdir_far[3], org_rdir_near[3], org_rdir_far[3];
    WatertightRay wt;
    float tmin;

    RayState(float3 o, float3 d, float t0) {
        const float org[3] = {o.x, o.y, o.z}, dir[3] = {d.x, d.y, d.z};
        for (int k = 0; k < 3; ++k) {
            const float limit =
                std::min(kMaxInverse, kMaxOverInverse / std::max(std::fabs(org[k]), 1.0f));
            const float r = std::clamp(1.0f / dir[k], -limit, limit);
            const float r_far = r * kFarScale;
            const float od = org[k] * r, err = std::fabs(od) * 0x1p-21f;
            rdir_near[k] = r;
            rdir_far[k] = r_far;
            org_rdir_near[k] = od + err;
            org_rdir_far[k] = org[k] * r_far - err;
            const bool neg = std::signbit(dir[k]);
            near_plane[k] = 16 * k + (neg ? 8 : 0);
            far_plane[k] = 16 * k + (neg ? 0 : 8);
        }
        wt = make_watertight_ray(o, d);
        tmin = t0;
        kx = wt.kx, ky = wt.ky, kz = wt.kz;
    }
#endif
};

/// The ray's current end with the broadcasts the tests compare against, computed when a
/// hit moves it rather than at every node.
struct RayEnd {
    float t;
#if LUCENT_ACCEL_SIMD
    __m256 t8;    // for the block tests
    __m256 far8;  // t * kFarScale for the node tests: a box entered within rounding of t
                  // stays in, like the far planes
#endif
    explicit RayEnd(float tmax) {
        set(tmax);
    }
    void set(float tmax) {
        t = tmax;
#if LUCENT_ACCEL_SIMD
        t8 = _mm256_set1_ps(tmax);
        far8 = _mm256_set1_ps(tmax * kFarScale);
#endif
    }
};

/// Slab test of the eight children: returns the hit mask and writes entry distances.
inline unsigned test_node(const WideNode& node, const RayState& r, const RayEnd& end, float* dist) {
    const float* p = &node.planes[0][0][0];
#if LUCENT_ACCEL_SIMD
    __m256 tn[3], tf[3];
    for (int k = 0; k < 3; ++k) {
        tn[k] = _mm256_fmsub_ps(_mm256_load_ps(p + r.near_plane[k]), r.rdir_near8[k],
                                r.org_rdir_near8[k]);
        tf[k] =
            _mm256_fmsub_ps(_mm256_load_ps(p + r.far_plane[k]), r.rdir_far8[k], r.org_rdir_far8[k]);
    }
    __m256 t_near = _mm256_max_ps(_mm256_max_ps(tn[0], tn[1]), _mm256_max_ps(tn[2], r.tmin8));
    const __m256 t_far = _mm256_min_ps(_mm256_min_ps(tf[0], tf[1]), _mm256_min_ps(tf[2], end.far8));
    _mm256_storeu_ps(dist, t_near);
    return (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(t_near, t_far, _CMP_LE_OQ));
#else
    unsigned mask = 0;
    for (int i = 0; i < kWideArity; ++i) {
        float t_near = r.tmin, t_far = end.t * kFarScale;
        for (int k = 0; k < 3; ++k) {
            t_near = lc_max(t_near,
                            std::fma(p[r.near_plane[k] + i], r.rdir_near[k], -r.org_rdir_near[k]));
            t_far =
                lc_min(t_far, std::fma(p[r.far_plane[k] + i], r.rdir_far[k], -r.org_rdir_far[k]));
        }
        dist[i] = t_near;
        if (t_near <= t_far) mask |= 1u << i;
    }
    return mask;
#endif
}

/// The slab test of the eight children as test_node, and in `inside` those whose boxes the
/// ray passes wholly through: entered after tmin and left before tmax (the leaf-box
/// occlusion query's test).
inline unsigned test_node_inside(const WideNode& node, const RayState& r, const RayEnd& end,
                                 unsigned& inside) {
    const float* p = &node.planes[0][0][0];
#if LUCENT_ACCEL_SIMD
    __m256 tn[3], tf[3];
    for (int k = 0; k < 3; ++k) {
        tn[k] = _mm256_fmsub_ps(_mm256_load_ps(p + r.near_plane[k]), r.rdir_near8[k],
                                r.org_rdir_near8[k]);
        tf[k] =
            _mm256_fmsub_ps(_mm256_load_ps(p + r.far_plane[k]), r.rdir_far8[k], r.org_rdir_far8[k]);
    }
    const __m256 raw_near = _mm256_max_ps(_mm256_max_ps(tn[0], tn[1]), tn[2]);
    const __m256 raw_far = _mm256_min_ps(_mm256_min_ps(tf[0], tf[1]), tf[2]);
    const __m256 t_near = _mm256_max_ps(raw_near, r.tmin8);
    const __m256 t_far = _mm256_min_ps(raw_far, end.far8);
    const unsigned hit = (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(t_near, t_far, _CMP_LE_OQ));
    const __m256 within = _mm256_and_ps(_mm256_cmp_ps(raw_near, r.tmin8, _CMP_GT_OQ),
                                        _mm256_cmp_ps(raw_far, end.t8, _CMP_LT_OQ));
    inside = hit & (unsigned)_mm256_movemask_ps(within);
    return hit;
#else
    unsigned hit = 0;
    inside = 0;
    for (int i = 0; i < kWideArity; ++i) {
        float raw_near = -kInfinity, raw_far = kInfinity;
        for (int k = 0; k < 3; ++k) {
            raw_near = lc_max(raw_near, std::fma(p[r.near_plane[k] + i], r.rdir_near[k],
                                                 -r.org_rdir_near[k]));
            raw_far = lc_min(raw_far,
                             std::fma(p[r.far_plane[k] + i], r.rdir_far[k], -r.org_rdir_far[k]));
        }
        if (lc_max(raw_near, r.tmin) > lc_min(raw_far, end.t * kFarScale)) continue;
        hit |= 1u << i;
        if (raw_near > r.tmin && raw_far < end.t) inside |= 1u << i;
    }
    return hit;
#endif
}

/// The children of `node` in `mask` that are leaves.
inline unsigned leaf_children(const WideNode& node, unsigned mask) {
#if LUCENT_ACCEL_SIMD
    // kLeafBit is each reference's sign bit: one movemask reads all eight, where a loop
    // over the hit children took a branch on each (a sixth of the query's time).
    static_assert(kLeafBit == 0x80000000u);
    const __m256i children = _mm256_load_si256(reinterpret_cast<const __m256i*>(node.child));
    return mask & (unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(children));
#else
    unsigned leaves = 0;
    for (; mask != 0; mask &= mask - 1) {
        const unsigned c = (unsigned)std::countr_zero(mask);
        if (is_leaf(node.child[c])) leaves |= 1u << c;
    }
    return leaves;
#endif
}

#if LUCENT_ACCEL_SIMD
/// The operations of the watertight block test on four lanes (SSE) or eight (AVX), so one
/// template serves both block widths.
template <int kLanes>
struct Lanes;

template <>
struct Lanes<4> {
    using V = __m128;
    static V load(const float* p) { return _mm_load_ps(p); }
    static V zero() { return _mm_setzero_ps(); }
    static V from8(__m256 x) { return _mm256_castps256_ps128(x); }
    static V add(V a, V b) { return _mm_add_ps(a, b); }
    static V sub(V a, V b) { return _mm_sub_ps(a, b); }
    static V mul(V a, V b) { return _mm_mul_ps(a, b); }
    static V div(V a, V b) { return _mm_div_ps(a, b); }
    static V fmadd(V a, V b, V c) { return _mm_fmadd_ps(a, b, c); }
    static V fmsub(V a, V b, V c) { return _mm_fmsub_ps(a, b, c); }
    static V fnmadd(V a, V b, V c) { return _mm_fnmadd_ps(a, b, c); }
    static V and_(V a, V b) { return _mm_and_ps(a, b); }
    static V or_(V a, V b) { return _mm_or_ps(a, b); }
    static V andnot(V a, V b) { return _mm_andnot_ps(a, b); }
    template <int kCmp>
    static V cmp(V a, V b) {
        return _mm_cmp_ps(a, b, kCmp);
    }
    static unsigned mask(V a) { return (unsigned)_mm_movemask_ps(a); }
    static void store(float* p, V a) { _mm_store_ps(p, a); }
};

template <>
struct Lanes<8> {
    using V = __m256;
    static V load(const float* p) { return _mm256_load_ps(p); }
    static V zero() { return _mm256_setzero_ps(); }
    static V from8(__m256 x) { return x; }
    static V add(V a, V b) { return _mm256_add_ps(a, b); }
    static V sub(V a, V b) { return _mm256_sub_ps(a, b); }
    static V mul(V a, V b) { return _mm256_mul_ps(a, b); }
    static V div(V a, V b) { return _mm256_div_ps(a, b); }
    static V fmadd(V a, V b, V c) { return _mm256_fmadd_ps(a, b, c); }
    static V fmsub(V a, V b, V c) { return _mm256_fmsub_ps(a, b, c); }
    static V fnmadd(V a, V b, V c) { return _mm256_fnmadd_ps(a, b, c); }
    static V and_(V a, V b) { return _mm256_and_ps(a, b); }
    static V or_(V a, V b) { return _mm256_or_ps(a, b); }
    static V andnot(V a, V b) { return _mm256_andnot_ps(a, b); }
    template <int kCmp>
    static V cmp(V a, V b) {
        return _mm256_cmp_ps(a, b, kCmp);
    }
    static unsigned mask(V a) { return (unsigned)_mm256_movemask_ps(a); }
    static void store(float* p, V a) { _mm256_store_ps(p, a); }
};

/// a*b - c*d on every lane, with the same operations as difference_of_products().
template <class L>
inline typename L::V difference_of_products(typename L::V a, typename L::V b, typename L::V c,
                                            typename L::V d) {
    const typename L::V cd = L::mul(c, d);
    const typename L::V err = L::fnmadd(c, d, cd);
    return L::add(L::fmsub(a, b, cd), err);
}
#endif

/// What the watertight test of a block leaves per lane: the distance, and the scaled
/// barycentrics of vertices 1 and 2 with their denominator, so that a hit's (u, v) are
/// two divisions away instead of a second test.
struct BlockLanes {
    alignas(32) float t[kMaxLeafTriangles];
    alignas(32) float e1[kMaxLeafTriangles];
    alignas(32) float e2[kMaxLeafTriangles];
    alignas(32) float det[kMaxLeafTriangles];
};

/// Watertight test of the `count` triangles of a block against (tmin, tmax): returns the
/// lanes hit and writes their distances and edge functions.
template <int kLanes>
inline unsigned test_block(const TriangleBlock<kLanes>& block, uint32_t count, const RayState& r,
                           const RayEnd& end, BlockLanes& out) {
#if LUCENT_ACCEL_SIMD
    using L = Lanes<kLanes>;
    using V = typename L::V;
    const float* v0 = &block.vertex[0][0][0];
    const float* v1 = &block.vertex[1][0][0];
    const float* v2 = &block.vertex[2][0][0];
    const int kx = kLanes * r.kx, ky = kLanes * r.ky, kz = kLanes * r.kz;
    const V ox = L::from8(r.ox8), oy = L::from8(r.oy8), oz = L::from8(r.oz8);
    const V sx = L::from8(r.sx8), sy = L::from8(r.sy8), sz = L::from8(r.sz8);
    const V az = L::sub(L::load(v0 + kz), oz);
    const V bz = L::sub(L::load(v1 + kz), oz);
    const V cz = L::sub(L::load(v2 + kz), oz);
    const V ax = L::fnmadd(sx, az, L::sub(L::load(v0 + kx), ox));
    const V ay = L::fnmadd(sy, az, L::sub(L::load(v0 + ky), oy));
    const V bx = L::fnmadd(sx, bz, L::sub(L::load(v1 + kx), ox));
    const V by = L::fnmadd(sy, bz, L::sub(L::load(v1 + ky), oy));
    const V cx = L::fnmadd(sx, cz, L::sub(L::load(v2 + kx), ox));
    const V cy = L::fnmadd(sy, cz, L::sub(L::load(v2 + ky), oy));
    const V e0 = difference_of_products<L>(cx, by, cy, bx);
    const V e1 = difference_of_products<L>(ax, cy, ay, cx);
    const V e2 = difference_of_products<L>(bx, ay, by, ax);
    const V zero = L::zero();
    const V neg =
        L::or_(L::or_(L::template cmp<_CMP_LT_OQ>(e0, zero), L::template cmp<_CMP_LT_OQ>(e1, zero)),
               L::template cmp<_CMP_LT_OQ>(e2, zero));
    const V pos =
        L::or_(L::or_(L::template cmp<_CMP_GT_OQ>(e0, zero), L::template cmp<_CMP_GT_OQ>(e1, zero)),
               L::template cmp<_CMP_GT_OQ>(e2, zero));
    const V det = L::add(L::add(e0, e1), e2);
    const V inside = L::andnot(L::and_(neg, pos), L::template cmp<_CMP_NEQ_UQ>(det, zero));
    unsigned mask = L::mask(inside) & ((1u << count) - 1);
    if (mask == 0) return 0;
    const V scaled =
        L::fmadd(e2, L::mul(sz, cz), L::fmadd(e1, L::mul(sz, bz), L::mul(e0, L::mul(sz, az))));
    const V t = L::div(scaled, det);
    const V in_range = L::and_(L::template cmp<_CMP_GT_OQ>(t, L::from8(r.tmin8)),
                               L::template cmp<_CMP_LT_OQ>(t, L::from8(end.t8)));
    mask &= L::mask(in_range);
    L::store(out.t, t);
    L::store(out.e1, e1);
    L::store(out.e2, e2);
    L::store(out.det, det);
    return mask;
#else
    unsigned mask = 0;
    for (uint32_t lane = 0; lane < count; ++lane) {
        float3 p[3];
        for (int k = 0; k < 3; ++k)
            p[k] = make_float3(block.vertex[k][0][lane], block.vertex[k][1][lane],
                               block.vertex[k][2][lane]);
        float u, v;
        if (intersect_triangle_watertight(r.wt, p[0], p[1], p[2], r.tmin, end.t, out.t[lane], u,
                                          v)) {
            // (u, v) = (e1, e2) / det: a denominator of 1 hands them over unchanged.
            out.e1[lane] = u, out.e2[lane] = v, out.det[lane] = 1.0f;
            mask |= 1u << lane;
        }
    }
    return mask;
#endif
}

/// Asks for the memory of a child about to be tested: a node's four cache lines, a block's
/// three or five. Diffuse rays miss in L2 on about every node (Sponza's tree is 0.9 MB of
/// nodes and 3.6 MB of blocks); fetching all the hit children at once overlaps those misses.
inline void prefetch_child(const TriangleAccel::Impl& accel, uint32_t ref) {
#if LUCENT_ACCEL_SIMD
    static_assert(sizeof(TriangleBlock4) == 3 * 64 && sizeof(TriangleBlock8) == 5 * 64);
    if (is_wide_leaf(ref)) {
        const char* p = reinterpret_cast<const char*>(&accel.blocks8[leaf_block(ref)]);
        for (int line = 0; line < 5; ++line) _mm_prefetch(p + 64 * line, _MM_HINT_T0);
    } else if (is_leaf(ref)) {
        const char* p = reinterpret_cast<const char*>(&accel.blocks4[leaf_block(ref)]);
        _mm_prefetch(p, _MM_HINT_T0);
        _mm_prefetch(p + 64, _MM_HINT_T0);
        _mm_prefetch(p + 128, _MM_HINT_T0);
    } else {
        const char* p = reinterpret_cast<const char*>(&accel.nodes[ref]);
        static_assert(sizeof(WideNode) == 4 * 64);
        _mm_prefetch(p, _MM_HINT_T0);
        _mm_prefetch(p + 64, _MM_HINT_T0);
        _mm_prefetch(p + 128, _MM_HINT_T0);
        _mm_prefetch(p + 192, _MM_HINT_T0);
    }
#else
    (void)accel, (void)ref;
#endif
}

/// Pushes the children in `mask`, unordered, without their distances (an occlusion ray
/// never compares them). With AVX-512 one compress moves the hit children together and one
/// store writes them, eight slots wide; without, a loop per child.
inline void push_children(const WideNode& node, unsigned mask, uint32_t* stack_ref,
                          float* stack_dist, const float* dist, int& sp) {
#if LUCENT_ACCEL_SIMD && defined(__AVX512VL__)
    (void)stack_dist, (void)dist;
    const __m256i children = _mm256_load_si256(reinterpret_cast<const __m256i*>(node.child));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(stack_ref + sp),
                        _mm256_maskz_compress_epi32(__mmask8(mask), children));
    sp += std::popcount(mask);
#else
    do {
        const unsigned c = (unsigned)std::countr_zero(mask);
        mask &= mask - 1;
        stack_ref[sp] = node.child[c];
        stack_dist[sp++] = dist[c];
    } while (mask != 0);
#endif
}

#if LUCENT_ACCEL_SIMD && !defined(__AVX512VL__)
/// For each 8-bit mask, the indices of its set bits in order, one per byte, the rest 0:
/// AVX2's stand-in for AVX-512's compress (a permutation that moves the chosen lanes down).
struct CompressTable {
    uint64_t lanes[256];
    constexpr CompressTable() : lanes{} {
        for (unsigned m = 0; m < 256; ++m) {
            unsigned k = 0;
            for (unsigned c = 0; c < 8; ++c)
                if (m & (1u << c)) lanes[m] |= uint64_t(c) << (8 * k++);
        }
    }
};
constexpr CompressTable kCompress;
#endif

/// Pushes the children in `mask` (which may be empty) without a branch on the mask: one
/// compress and one eight-slot store (AVX-512), or a table's permutation (AVX2). The
/// leaf-box query's loop has no data-dependent branch but its two exits.
inline void push_children_branchless(const WideNode& node, unsigned mask, uint32_t* stack_ref,
                                     unsigned& sp) {
#if LUCENT_ACCEL_SIMD
    const __m256i children = _mm256_load_si256(reinterpret_cast<const __m256i*>(node.child));
#if defined(__AVX512VL__)
    const __m256i packed = _mm256_maskz_compress_epi32(__mmask8(mask), children);
#else
    const __m256i order = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128((long long)kCompress.lanes[mask]));
    const __m256i packed = _mm256_permutevar8x32_epi32(children, order);
#endif
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(stack_ref + sp), packed);
    sp += std::popcount(mask);
#else
    for (; mask != 0; mask &= mask - 1) stack_ref[sp++] = node.child[std::countr_zero(mask)];
#endif
}

/// A node of eight empty slots, tested where a step of the leaf-box query has fewer nodes
/// to test than it has places: its inverted boxes are never hit.
struct NoNode {
    WideNode node;
    NoNode() {
        for (int k = 0; k < 3; ++k)
            for (int i = 0; i < kWideArity; ++i) {
                node.planes[k][0][i] = kInfinity;
                node.planes[k][1][i] = -kInfinity;
            }
        for (int i = 0; i < kWideArity; ++i) node.child[i] = kEmptyChild;
    }
};
const NoNode kNoNode;

/// Nodes the leaf-box query tests per step. A Sponza VPL shadow ray's walk is a chain of
/// dependent steps (pop, load, slab test, mask, push: about 50 cycles), not a lack of
/// throughput, so two independent node tests per step nearly halve the chain: measured on
/// 600,000 of its rays, 1.2x the one-node loop (8.2 steps a ray become 5.5, 8.8 nodes
/// tested). Three gave 1.15x and four 1.05x: the steps cannot go below the tree's depth,
/// and the extra tests are of the empty node.
constexpr int kLeafBoxNodesPerStep = 2;

/// The leaf-box occlusion query (TriangleAccel::occluded_leaf_boxes): inner nodes only. A
/// leaf the ray passes wholly through answers it; a leaf it enters otherwise holds an end
/// of the ray and is skipped, so no triangle is ever loaded. Every reference on the stack is
/// therefore an inner node, and the answer (is some leaf box wholly within the segment?)
/// does not depend on the order the nodes are visited in. That is what lets each step pop
/// and test kLeafBoxNodesPerStep nodes at once without branches between them, which the
/// exact query, whose stack mixes nodes and leaves of different work, cannot do as simply.
bool traverse_leaf_boxes(const TriangleAccel::Impl& accel, float3 origin, float3 direction,
                         float tmin, float tmax) {
    constexpr int K = kLeafBoxNodesPerStep;
    const RayState r(origin, direction, tmin);
    const RayEnd end(tmax);
    // stack[1..sp] holds the nodes to visit; stack[0] is read (and not taken) when the
    // stack runs out within a step. The push may write eight past the top.
    uint32_t stack[kStackSize + kWideArity + 1];
    stack[0] = 0;
    unsigned sp = 0;
    const WideNode* node[K];
    node[0] = &accel.nodes[0];  // the root: always a node (a one-leaf tree has one)
    for (int k = 1; k < K; ++k) node[k] = &kNoNode.node;
    for (;;) {
        unsigned blocked = 0, inner[K];
        for (int k = 0; k < K; ++k) {
            unsigned inside = 0;
            const unsigned hit = test_node_inside(*node[k], r, end, inside);
            const unsigned leaves = leaf_children(*node[k], hit);
            blocked |= inside & leaves;
            inner[k] = hit & ~leaves;
        }
        if (blocked) return true;
        for (int k = 0; k < K; ++k) push_children_branchless(*node[k], inner[k], stack + 1, sp);
        if (sp == 0) return false;
        for (int k = 0; k < K; ++k) {
            const bool take = sp > 0;
            const WideNode* next = &accel.nodes[stack[sp]];
            node[k] = take ? next : &kNoNode.node;
            sp -= take;
        }
    }
}

enum class Query { kClosest, kAny, kFiltered };

/// The one traversal loop, specialized per query. Closest and filtered queries visit the
/// children nearest first and drop stack entries beyond the current closest hit.
template <Query kQuery>
bool traverse(const TriangleAccel::Impl& accel, float3 origin, float3 direction, float tmin,
              float tmax, TriangleHit* hit, FilterThunk thunk, void* filter) {
    const RayState r(origin, direction, tmin);
    RayEnd end(tmax);
    uint32_t stack_ref[kStackSize + kWideArity];  // push_children may write 8 past the top
    float stack_dist[kStackSize];
    int sp = 0;
    uint32_t ref = 0;
    bool found = false;
    uint32_t best_prim = 0, best_lanes = 0;
    const float* best_vertex = nullptr;
    float best_e1 = 0.0f, best_e2 = 0.0f, best_det = 1.0f;
    alignas(32) float dist[kWideArity];
    BlockLanes lanes;
    for (;;) {
        if (!is_leaf(ref)) {
            const WideNode& node = accel.nodes[ref];
#if LUCENT_ACCEL_SIMD
            // The child references are the node's fourth cache line, read only once the
            // test is done: ask for it now, beside the three the test reads.
            _mm_prefetch(reinterpret_cast<const char*>(node.child), _MM_HINT_T0);
#endif
            unsigned mask = test_node(node, r, end, dist);
            if (mask != 0) {
                unsigned c0 = (unsigned)std::countr_zero(mask);
                mask &= mask - 1;
                if (mask == 0) {
                    ref = node.child[c0];
                    continue;
                }
                if constexpr (kQuery == Query::kAny) {
                    // Order does not matter for occlusion: go down the first, keep the rest.
                    push_children(node, mask, stack_ref, stack_dist, dist, sp);
                    ref = node.child[c0];
                    continue;
                } else {
                    // Occlusion rays gain nothing from this (-5 %, and within the spread
                    // again with the fixed bench harness): a closest-hit ray visits most of
                    // the children it pushes, an occlusion ray often stops at the first.
                    prefetch_child(accel, node.child[c0]);
                    for (unsigned m = mask; m != 0; m &= m - 1)
                        prefetch_child(accel, node.child[std::countr_zero(m)]);
                    unsigned c1 = (unsigned)std::countr_zero(mask);
                    mask &= mask - 1;
                    if (mask == 0) {
                        if (dist[c1] < dist[c0]) std::swap(c0, c1);
                        stack_ref[sp] = node.child[c1];
                        stack_dist[sp++] = dist[c1];
                        ref = node.child[c0];
                        continue;
                    }
                    // Three or more: push all, sort them far to near, continue with the nearest.
                    const int base = sp;
                    stack_ref[sp] = node.child[c0];
                    stack_dist[sp++] = dist[c0];
                    stack_ref[sp] = node.child[c1];
                    stack_dist[sp++] = dist[c1];
                    do {
                        unsigned c = (unsigned)std::countr_zero(mask);
                        mask &= mask - 1;
                        stack_ref[sp] = node.child[c];
                        stack_dist[sp++] = dist[c];
                    } while (mask != 0);
                    for (int i = base + 1; i < sp; ++i) {
                        float d = stack_dist[i];
                        uint32_t c = stack_ref[i];
                        int j = i - 1;
                        while (j >= base && stack_dist[j] < d) {
                            stack_dist[j + 1] = stack_dist[j];
                            stack_ref[j + 1] = stack_ref[j];
                            --j;
                        }
                        stack_dist[j + 1] = d;
                        stack_ref[j + 1] = c;
                    }
                    ref = stack_ref[--sp];
                    continue;
                }
            }
        } else if (ref != kEmptyChild) {
            const uint32_t count = leaf_count(ref);
            const uint32_t* prims;
            const float* vertices;  // the block's vertex[0][0]
            uint32_t block_lanes;
            unsigned mask;
            if (count > kNarrowLeafTriangles) {
                const TriangleBlock8& block = accel.blocks8[leaf_block(ref)];
                mask = test_block(block, count, r, end, lanes);
                prims = block.prim;
                vertices = &block.vertex[0][0][0];
                block_lanes = 8;
            } else {
                const TriangleBlock4& block = accel.blocks4[leaf_block(ref)];
                mask = test_block(block, count, r, end, lanes);
                prims = block.prim;
                vertices = &block.vertex[0][0][0];
                block_lanes = 4;
            }
            if (mask != 0) {
                if constexpr (kQuery == Query::kAny) {
                    return true;
                } else if constexpr (kQuery == Query::kClosest) {
                    do {
                        int lane = std::countr_zero(mask);
                        mask &= mask - 1;
                        if (lanes.t[lane] < tmax) {
                            tmax = lanes.t[lane];
                            best_prim = prims[lane];
                            best_vertex = vertices + lane;
                            best_lanes = block_lanes;
                            best_e1 = lanes.e1[lane];
                            best_e2 = lanes.e2[lane];
                            best_det = lanes.det[lane];
                        }
                    } while (mask != 0);
                    end.set(tmax);
                    found = true;
                } else {
                    do {
                        int lane = std::countr_zero(mask);
                        mask &= mask - 1;
                        if (!(lanes.t[lane] < tmax)) continue;
                        TriangleHit candidate;
                        candidate.t = lanes.t[lane];
                        candidate.prim = prims[lane];
                        candidate.vertex_lane = vertices + lane;
                        candidate.lanes = block_lanes;
                        store_barycentrics(candidate, lanes.e1[lane], lanes.e2[lane],
                                           lanes.det[lane]);
                        HitDecision decision = thunk(filter, candidate);
                        if (decision == HitDecision::kIgnore) continue;
                        *hit = candidate;
                        found = true;
                        tmax = candidate.t;
                        end.set(tmax);
                        if (decision == HitDecision::kAcceptAndStop) return true;
                    } while (mask != 0);
                }
            }
        }
        // Pop the next entry that may still hold a nearer hit.
        for (;;) {
            if (sp == 0) {
                if constexpr (kQuery == Query::kClosest) {
                    if (found) {
                        hit->t = tmax;
                        hit->prim = best_prim;
                        hit->vertex_lane = best_vertex;
                        hit->lanes = best_lanes;
                        store_barycentrics(*hit, best_e1, best_e2, best_det);
                    }
                }
                return found;
            }
            --sp;
            if (kQuery == Query::kAny || stack_dist[sp] <= tmax) break;
        }
        ref = stack_ref[sp];
    }
}

}  // namespace

bool intersect(const TriangleAccel::Impl& accel, float3 origin, float3 direction, float tmin,
               float tmax, TriangleHit& hit) {
    return traverse<Query::kClosest>(accel, origin, direction, tmin, tmax, &hit, nullptr, nullptr);
}

bool occluded(const TriangleAccel::Impl& accel, float3 origin, float3 direction, float tmin,
              float tmax) {
    return traverse<Query::kAny>(accel, origin, direction, tmin, tmax, nullptr, nullptr, nullptr);
}

bool occluded_leaf_boxes(const TriangleAccel::Impl& accel, float3 origin, float3 direction,
                         float tmin, float tmax) {
    return traverse_leaf_boxes(accel, origin, direction, tmin, tmax);
}

bool intersect_filtered(const TriangleAccel::Impl& accel, float3 origin, float3 direction,
                        float tmin, float tmax, TriangleHit& hit, FilterThunk thunk, void* filter) {
    return traverse<Query::kFiltered>(accel, origin, direction, tmin, tmax, &hit, thunk, filter);
}

// The stream queries (triangle_stream.cpp, the same variant).
void intersect_stream(const TriangleAccel::Impl& accel, const StreamRay* rays, size_t count,
                      StreamHit* hits, StreamBuffers& buffers);
void occluded_stream(const TriangleAccel::Impl& accel, const StreamRay* rays, size_t count,
                     uint8_t* blocked, StreamBuffers& buffers);

extern const TraverseVariant kTraverse = {
    intersect,
    occluded,
    occluded_leaf_boxes,
    intersect_filtered,
    intersect_stream,
    occluded_stream,
#if !LUCENT_ACCEL_SIMD
    "scalar",
#elif defined(__AVX512VL__)
    "avx2 fma avx512vl",
#else
    "avx2 fma",
#endif
};

}  // namespace lucent::accel::LUCENT_ISA_VARIANT

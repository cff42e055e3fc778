// Acceleration structures against brute force: the binary Bvh (generic traversal, refit,
// depth bound), TriangleAccel (closest, any, filtered, refit, watertightness) on random
// soups and on the benchmark scenes, the choice of the traversal's instruction-set variant,
// and the OBJ loader's errors. tests/CMakeLists.txt runs the TriangleAccel and CpuIsa tests
// again on each variant the CPU supports, chosen with LUCENT_CPU_ISA.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <vector>

#include "accel/bvh.h"
#include "accel/cpu_isa.h"
#include "accel/ray_stream.h"
#include "accel/triangle_accel.h"
#include "accel/triangle_traverse.h"
#include "lucent/device/triangle_intersect.h"
#include "lucent/error.h"
#include "scene/obj_mesh.h"
#include "tests/mesh_fixtures.h"

namespace lucent::accel {
namespace {

using test_meshes::floor_and_clutter;
using test_meshes::Mesh;

struct BruteHit {
    bool hit = false;
    float t = 0, u = 0, v = 0;
    uint32_t prim = 0;
};

/// Closest hit over all triangles with the scalar watertight test; `keep(prim)` filters.
template <class Keep>
BruteHit brute_force(const Mesh& m, float3 o, float3 d, float tmin, float tmax, Keep&& keep) {
    const WatertightRay r = make_watertight_ray(o, d);
    BruteHit best;
    for (uint32_t i = 0; i < m.indices.size(); ++i) {
        if (!keep(i)) continue;
        uint3 t = m.indices[i];
        float th, u, v;
        if (intersect_triangle_watertight(r, m.positions[t.x], m.positions[t.y], m.positions[t.z],
                                          tmin, best.hit ? best.t : tmax, th, u, v))
            best = BruteHit{true, th, u, v, i};
    }
    return best;
}
BruteHit brute_force(const Mesh& m, float3 o, float3 d, float tmin, float tmax) {
    return brute_force(m, o, d, tmin, tmax, [](uint32_t) { return true; });
}

/// t of one triangle along the ray, or -1.
float triangle_t(const Mesh& m, uint32_t prim, float3 o, float3 d) {
    float t, u, v;
    uint3 tri = m.indices[prim];
    if (!intersect_triangle_watertight(make_watertight_ray(o, d), m.positions[tri.x],
                                       m.positions[tri.y], m.positions[tri.z], -kInfinity,
                                       kInfinity, t, u, v))
        return -1.0f;
    return t;
}

/// Random soup in [0,1]^3: ordinary, long thin, degenerate (collinear, repeated vertex)
/// and axis-aligned triangles.
Mesh random_soup(uint32_t seed, int count) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    Mesh m;
    for (int i = 0; i < count; ++i) {
        float3 c = make_float3(uni(rng), uni(rng), uni(rng));
        float s = 0.02f + 0.2f * uni(rng) * uni(rng);
        float3 a = c + s * make_float3(uni(rng) - .5f, uni(rng) - .5f, uni(rng) - .5f);
        float3 b = c + s * make_float3(uni(rng) - .5f, uni(rng) - .5f, uni(rng) - .5f);
        float3 e = c + s * make_float3(uni(rng) - .5f, uni(rng) - .5f, uni(rng) - .5f);
        switch (i % 10) {
            case 0:
                e = a + 0.37f * (b - a);
                break;  // collinear
            case 1:
                e = b;
                break;  // repeated vertex
            case 2:
                b = a + make_float3(0.6f * uni(rng), 1e-4f, 0);
                break;  // thin sliver
            case 3:
                a.z = b.z = e.z = c.z;
                break;  // axis-aligned
            default:
                break;
        }
        uint32_t base = (uint32_t)m.positions.size();
        m.positions.insert(m.positions.end(), {a, b, e});
        m.indices.push_back(make_uint3(base, base + 1, base + 2));
    }
    return m;
}

struct TestRay {
    float3 o, d;
    float tmin, tmax;
};

std::vector<TestRay> random_rays(uint32_t seed, int count) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    const float3 axes[6] = {make_float3(1, 0, 0),  make_float3(-1, 0, 0), make_float3(0, 1, 0),
                            make_float3(0, -1, 0), make_float3(0, 0, 1),  make_float3(0, 0, -1)};
    std::vector<TestRay> rays;
    for (int i = 0; i < count; ++i) {
        TestRay r;
        bool inside = i % 2 == 0;  // half start inside the soup
        r.o = inside ? make_float3(uni(rng), uni(rng), uni(rng))
                     : make_float3(uni(rng) * 3 - 1, uni(rng) * 3 - 1, uni(rng) * 3 - 1);
        float3 target = make_float3(uni(rng), uni(rng), uni(rng));
        r.d = i % 7 == 0 ? axes[i % 6] : normalize(target - r.o);
        if (i % 11 == 0) r.d = r.d * 3.5f;  // unnormalized directions
        r.tmin = i % 5 == 0 ? 0.05f : 0.0f;
        r.tmax = i % 3 == 0 ? 0.4f : kInfinity;
        rays.push_back(r);
    }
    return rays;
}

/// The accel's closest hit must be brute force's: same t (same arithmetic), and a
/// triangle that really is hit at that t (ties may pick either triangle).
void expect_same_closest(const Mesh& m, const TriangleAccel& accel, const TestRay& r) {
    TriangleHit hit;
    const bool found = accel.intersect(r.o, r.d, r.tmin, r.tmax, hit);
    const BruteHit ref = brute_force(m, r.o, r.d, r.tmin, r.tmax);
    ASSERT_EQ(found, ref.hit);
    if (!found) return;
    EXPECT_EQ(hit.t, ref.t);
    EXPECT_EQ(triangle_t(m, hit.prim, r.o, r.d), hit.t);
    if (hit.prim == ref.prim) {
        EXPECT_EQ(hit.u, ref.u);
        EXPECT_EQ(hit.v, ref.v);
    }
}

TEST(Bvh, EmptyInputGivesEmptyTree) {
    Bvh bvh;
    bvh.build({});
    EXPECT_TRUE(bvh.empty());
    float tmax = kInfinity;
    int visits = 0;
    bvh.traverse(make_float3(0), make_float3(1, 0, 0), 0.0f, tmax, [&](uint32_t) {
        ++visits;
        return false;
    });
    EXPECT_EQ(visits, 0);
    TriangleAccel accel;
    accel.build({}, {});
    TriangleHit hit;
    EXPECT_FALSE(accel.intersect(make_float3(0), make_float3(1, 0, 0), 0, kInfinity, hit));
    EXPECT_FALSE(accel.occluded(make_float3(0), make_float3(1, 0, 0), 0, kInfinity));
}

TEST(Bvh, StructureIsValid) {
    Mesh m = random_soup(7, 3000);
    std::vector<Aabb> boxes;
    for (uint3 t : m.indices) {
        float3 a = m.positions[t.x], b = m.positions[t.y], c = m.positions[t.z];
        boxes.push_back(Aabb{fminf(a, fminf(b, c)), fmaxf(a, fmaxf(b, c))});
    }
    Bvh bvh;
    BuildStats stats;
    bvh.build(boxes, {}, &stats);
    std::vector<int> seen(boxes.size(), 0);
    for (const BvhNode& n : bvh.nodes()) {
        if (n.count > 0) {
            EXPECT_LE(n.count, 4u);
            for (uint32_t i = 0; i < n.count; ++i) {
                uint32_t p = bvh.prim_order()[n.first + i];
                ++seen[p];
                EXPECT_LE(n.lo.x, boxes[p].lo.x);
                EXPECT_GE(n.hi.y, boxes[p].hi.y);
            }
        } else {
            for (int c = 0; c < 2; ++c) {
                const BvhNode& k = bvh.nodes()[n.first + c];
                EXPECT_LE(n.lo.x, k.lo.x);
                EXPECT_LE(n.lo.z, k.lo.z);
                EXPECT_GE(n.hi.y, k.hi.y);
            }
        }
    }
    for (int s : seen) EXPECT_EQ(s, 1);
    EXPECT_EQ(stats.node_count, bvh.nodes().size());
    EXPECT_GT(stats.sah_cost, 0.0);
    EXPECT_DOUBLE_EQ(stats.sah_cost, bvh.sah_cost());
}

TEST(Bvh, DepthStaysWithinTheStackOnAdversarialInput) {
    // Boxes at 2^-i: every SAH split peels off one box, so the tree would be a list.
    std::vector<Aabb> boxes;
    for (int i = 0; i < 4000; ++i) {
        float x = std::ldexp(1.0f, -(i % 120)) + i * 1e-30f;
        boxes.push_back(Aabb{make_float3(x, 0, 0), make_float3(x, 1, 1)});
    }
    for (int i = 0; i < 200; ++i) boxes.push_back(Aabb{make_float3(0.5f), make_float3(0.5f)});
    Bvh bvh;
    BuildStats stats;
    bvh.build(boxes, {}, &stats);
    EXPECT_LE(stats.depth, 60u);
    TriangleAccel accel;  // and the triangle accel over the same kind of input
    Mesh m;
    for (int i = 0; i < 3000; ++i) {
        float x = std::ldexp(1.0f, -(i % 120));
        uint32_t b = (uint32_t)m.positions.size();
        m.positions.insert(m.positions.end(),
                           {make_float3(x, 0, 0), make_float3(x, 1, 0), make_float3(x, 0, 1)});
        m.indices.push_back(make_uint3(b, b + 1, b + 2));
    }
    accel.build(m.positions, m.indices, {}, &stats);
    EXPECT_LE(stats.depth, 60u);
    TriangleHit hit;
    ASSERT_TRUE(
        accel.intersect(make_float3(2, 0.25f, 0.25f), make_float3(-1, 0, 0), 0, kInfinity, hit));
    EXPECT_EQ(hit.t, 1.0f);
}

TEST(Bvh, GenericTraversalEqualsBruteForce) {
    for (uint32_t seed : {1u, 2u, 3u}) {
        Mesh m = random_soup(seed, 1500);
        std::vector<Aabb> boxes;
        for (uint3 t : m.indices) {
            float3 a = m.positions[t.x], b = m.positions[t.y], c = m.positions[t.z];
            boxes.push_back(Aabb{fminf(a, fminf(b, c)), fmaxf(a, fmaxf(b, c))});
        }
        Bvh bvh;
        bvh.build(boxes);
        for (const TestRay& r : random_rays(seed + 100, 400)) {
            // Every box the ray overlaps must be visited, each primitive at most once.
            std::vector<int> visited(boxes.size(), 0);
            float tmax = r.tmax;
            bvh.traverse(r.o, r.d, r.tmin, tmax, [&](uint32_t p) {
                ++visited[p];
                return false;
            });
            for (size_t i = 0; i < boxes.size(); ++i) {
                ASSERT_LE(visited[i], 1);
                float t0 = r.tmin, t1 = r.tmax;
                bool overlap = true;
                for (int k = 0; k < 3; ++k) {
                    float o = k == 0 ? r.o.x : (k == 1 ? r.o.y : r.o.z);
                    float d = k == 0 ? r.d.x : (k == 1 ? r.d.y : r.d.z);
                    float lo = k == 0 ? boxes[i].lo.x : (k == 1 ? boxes[i].lo.y : boxes[i].lo.z);
                    float hi = k == 0 ? boxes[i].hi.x : (k == 1 ? boxes[i].hi.y : boxes[i].hi.z);
                    if (d == 0.0f) {
                        if (o < lo || o > hi) overlap = false;
                        continue;
                    }
                    float a = (lo - o) / d, b = (hi - o) / d;
                    t0 = std::max(t0, std::min(a, b));
                    t1 = std::min(t1, std::max(a, b));
                }
                // Only clear overlaps: boxes grazed within rounding may go either way.
                if (overlap && t0 < t1 * 0.9999f - 1e-6f) {
                    EXPECT_EQ(visited[i], 1) << i;
                }
            }
            // Closest hit through the callback, shortening tmax as it goes.
            BruteHit ref = brute_force(m, r.o, r.d, r.tmin, r.tmax);
            WatertightRay wr = make_watertight_ray(r.o, r.d);
            float best = r.tmax;
            bool found = false;
            bvh.traverse(r.o, r.d, r.tmin, best, [&](uint32_t p) {
                uint3 t = m.indices[p];
                float th, u, v;
                if (intersect_triangle_watertight(wr, m.positions[t.x], m.positions[t.y],
                                                  m.positions[t.z], r.tmin, best, th, u, v))
                    best = th, found = true;
                return false;
            });
            ASSERT_EQ(found, ref.hit);
            if (found) {
                EXPECT_EQ(best, ref.t);
            }
        }
    }
}

TEST(TriangleAccel, ClosestAndAnyHitEqualBruteForce) {
    for (uint32_t seed : {11u, 12u, 13u, 14u}) {
        Mesh m = random_soup(seed, 2000);
        TriangleAccel accel;
        accel.build(m.positions, m.indices);
        EXPECT_EQ(accel.triangle_count(), m.indices.size());
        for (const TestRay& r : random_rays(seed * 7, 600)) {
            expect_same_closest(m, accel, r);
            EXPECT_EQ(accel.occluded(r.o, r.d, r.tmin, r.tmax),
                      brute_force(m, r.o, r.d, r.tmin, r.tmax).hit);
        }
    }
}

/// The interval (t0, t1) in which the ray is inside `box` (t0 > t1: it misses).
void box_interval(const Aabb& box, const TestRay& r, float& t0, float& t1) {
    const float o[3] = {r.o.x, r.o.y, r.o.z}, d[3] = {r.d.x, r.d.y, r.d.z};
    const float lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z};
    t0 = -kInfinity, t1 = kInfinity;
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0.0f) {
            if (o[k] < lo[k] || o[k] > hi[k]) t0 = kInfinity;
            continue;
        }
        const float a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
        t0 = std::max(t0, std::min(a, b));
        t1 = std::min(t1, std::max(a, b));
    }
}

TEST(TriangleAccel, LeafBoxOcclusionEqualsBruteForceOverItsLeafBoxes) {
    // Occlusion::kLeafBoxes: blocked exactly when some leaf box lies wholly within the ray's
    // interval. Rays whose answer hangs on rounding (a box ending within 1e-4 of tmin or
    // tmax, or grazed) are skipped; the rest must agree. The sizes give a tree of one leaf
    // (the root's one child), one of a few levels, and a deeper one whose walks keep many
    // nodes on the stack (the query tests two nodes a step, so a step may find the stack
    // run out after its first).
    struct Case {
        uint32_t seed, triangles;
    };
    for (const Case c : {Case{21, 1500}, Case{22, 1500}, Case{23, 1500}, Case{24, 6},
                         Case{25, 30000}}) {
        const uint32_t seed = c.seed;
        Mesh m = random_soup(seed, c.triangles);
        TriangleAccel accel;
        accel.build(m.positions, m.indices);
        const std::vector<Aabb> leaves = accel.leaf_boxes();
        ASSERT_FALSE(leaves.empty());
        int blocked = 0, open = 0;
        for (const TestRay& r : random_rays(seed * 5, 800)) {
            bool clear_inside = false, ambiguous = false;
            const float margin = 1e-4f * std::max(1.0f, r.tmax - r.tmin);
            for (const Aabb& box : leaves) {
                float t0, t1;
                box_interval(box, r, t0, t1);
                if (!(t0 <= t1 + margin)) continue;  // missed (with room)
                const bool inside = t0 > r.tmin + margin && t1 < r.tmax - margin;
                const bool near_edge = std::fabs(t0 - r.tmin) <= margin ||
                                       std::fabs(t1 - r.tmax) <= margin || t1 - t0 <= margin;
                if (inside && t0 < t1 - margin) clear_inside = true;
                else if (near_edge || inside) ambiguous = true;
            }
            if (!clear_inside && ambiguous) continue;
            EXPECT_EQ(accel.occluded_leaf_boxes(r.o, r.d, r.tmin, r.tmax), clear_inside)
                << "seed " << seed;
            ++(clear_inside ? blocked : open);
        }
        if (c.triangles < 1000) {
            EXPECT_GT(open, 50) << "seed " << seed;
            continue;
        }
        EXPECT_GT(blocked, 50) << "the rays test both answers";
        EXPECT_GT(open, 50) << "the rays test both answers";
    }
}

TEST(TriangleAccel, FarFromTheOriginEqualsBruteForce) {
    // The slab test computes plane/d - o/d, whose rounding grows with |o|: a soup (with its
    // axis-aligned triangles and rays) moved far out must still lose no hit.
    const float3 offset = make_float3(1.0e5f, -2.0e5f, 3.0e4f);
    Mesh m = random_soup(21, 2000);
    for (float3& p : m.positions) p = p + offset;
    TriangleAccel accel;
    accel.build(m.positions, m.indices);
    for (TestRay r : random_rays(77, 1500)) {
        r.o = r.o + offset;
        expect_same_closest(m, accel, r);
        EXPECT_EQ(accel.occluded(r.o, r.d, r.tmin, r.tmax),
                  brute_force(m, r.o, r.d, r.tmin, r.tmax).hit);
    }
}

TEST(TriangleAccel, LeavesOfFiveToEightTrianglesEqualBruteForce) {
    // Triangles whose boxes coincide cannot be split by the SAH, so each cell of 5 to 8 of
    // them becomes one leaf, tested 8 lanes at once (4 for the cells of 3 and 4).
    std::vector<std::array<int, 3>> spanning;  // corner triples whose box is the whole cube
    for (int a = 0; a < 8; ++a)
        for (int b = a + 1; b < 8; ++b)
            for (int c = b + 1; c < 8; ++c)
                if (((a ^ b) | (a ^ c)) == 7) spanning.push_back({a, b, c});
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    Mesh m;
    for (int cell = 0; cell < 400; ++cell) {
        const float3 lo = make_float3(uni(rng), uni(rng), uni(rng));
        const float size = 0.01f + 0.05f * uni(rng);
        const int count = 3 + cell % 6;
        for (int i = 0; i < count; ++i) {
            const auto& tri = spanning[(size_t(cell) * 7 + size_t(i) * 5) % spanning.size()];
            const uint32_t base = (uint32_t)m.positions.size();
            for (int corner : tri)
                m.positions.push_back(lo + size * make_float3(float(corner & 1),
                                                              float((corner >> 1) & 1),
                                                              float((corner >> 2) & 1)));
            m.indices.push_back(make_uint3(base, base + 1, base + 2));
        }
    }
    TriangleAccel accel;
    BuildStats stats;
    accel.build(m.positions, m.indices, {}, &stats);
    EXPECT_GT(stats.large_leaf_count, 100u);
    EXPECT_LT(stats.large_leaf_count, stats.leaf_count);
    for (const TestRay& r : random_rays(31, 1500)) {
        expect_same_closest(m, accel, r);
        EXPECT_EQ(accel.occluded(r.o, r.d, r.tmin, r.tmax),
                  brute_force(m, r.o, r.d, r.tmin, r.tmax).hit);
    }
}

// ---- ray streams (ray_stream.h) ---------------------------------------------------------

/// The stream queries' answers for `rays` against the single-ray queries': the same
/// triangles found at the same t (a tie may name the other triangle, which must then be hit
/// at that t), the same barycentrics for the same triangle, the same occlusion.
void expect_streams_equal_single_rays(const Mesh& m, const TriangleAccel& accel,
                                      const std::vector<TestRay>& rays,
                                      RayStreamWorkspace& workspace) {
    std::vector<StreamRay> stream;
    for (const TestRay& r : rays) stream.push_back(StreamRay{r.o, r.tmin, r.d, r.tmax});
    std::vector<StreamHit> hits(rays.size());
    std::vector<uint8_t> blocked(rays.size(), 7);
    accel.intersect_stream(stream, hits, workspace);
    accel.occluded_stream(stream, blocked, workspace);
    size_t found = 0, occluded = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        const TestRay& r = rays[i];
        TriangleHit hit;
        const bool single = accel.intersect(r.o, r.d, r.tmin, r.tmax, hit);
        ASSERT_EQ(hits[i].prim != kStreamMiss, single) << "ray " << i;
        EXPECT_EQ(blocked[i], accel.occluded(r.o, r.d, r.tmin, r.tmax) ? 1 : 0) << "ray " << i;
        occluded += blocked[i];
        if (!single) continue;
        ++found;
        EXPECT_EQ(hits[i].t, hit.t) << "ray " << i;
        EXPECT_EQ(triangle_t(m, hits[i].prim, r.o, r.d), hits[i].t) << "ray " << i;
        if (hits[i].prim == hit.prim) {
            EXPECT_EQ(hits[i].u, hit.u) << "ray " << i;
            EXPECT_EQ(hits[i].v, hit.v) << "ray " << i;
        }
    }
    // Both kinds of answer occur, so neither comparison is vacuous.
    EXPECT_GT(found, rays.size() / 10);
    EXPECT_LT(found, rays.size());
    EXPECT_GT(occluded, 0u);
}

TEST(TriangleAccel, StreamQueriesEqualSingleRayQueries) {
    RayStreamWorkspace workspace;  // one for all meshes: it grows with the deepest tree
    for (uint32_t seed : {21u, 22u}) {
        Mesh m = random_soup(seed, 3000);
        TriangleAccel accel;
        accel.build(m.positions, m.indices);
        expect_streams_equal_single_rays(m, accel, random_rays(seed * 5, 5000), workspace);
        // A few rays, fewer than a vector's sixteen lanes, and a stream of one.
        expect_streams_equal_single_rays(m, accel, random_rays(seed * 3, 13), workspace);
    }
}

TEST(TriangleAccel, StreamQueriesCrossBatchesAndLargeLeaves) {
    // More rays than one batch takes, through a tree with leaves of 5 to 8 triangles.
    Mesh m = random_soup(41, 20000);
    TriangleAccel accel;
    BuildStats stats;
    accel.build(m.positions, m.indices, {}, &stats);
    EXPECT_GT(stats.large_leaf_count, 0u);
    RayStreamWorkspace workspace;
    expect_streams_equal_single_rays(m, accel, random_rays(43, int(kStreamBatch) + 1500),
                                     workspace);
}

TEST(TriangleAccel, StreamQueriesOnAnEmptyAccelMissEverything) {
    TriangleAccel accel;
    accel.build({}, {});
    RayStreamWorkspace workspace;
    const std::vector<StreamRay> rays(40, StreamRay{make_float3(0, 0, 0), 0.0f,
                                                    make_float3(0, 0, 1), kInfinity});
    std::vector<StreamHit> hits(rays.size());
    std::vector<uint8_t> blocked(rays.size(), 1);
    accel.intersect_stream(rays, hits, workspace);
    accel.occluded_stream(rays, blocked, workspace);
    for (size_t i = 0; i < rays.size(); ++i) {
        EXPECT_EQ(hits[i].prim, kStreamMiss);
        EXPECT_EQ(blocked[i], 0);
    }
}

TEST(TriangleAccel, StreamQueriesNameMismatchedSpans) {
    Mesh m = random_soup(3, 50);
    TriangleAccel accel;
    accel.build(m.positions, m.indices);
    RayStreamWorkspace workspace;
    const std::vector<StreamRay> rays(5, StreamRay{make_float3(0, 0, 0), 0.0f,
                                                   make_float3(0, 0, 1), kInfinity});
    std::vector<StreamHit> hits(4);
    std::vector<uint8_t> blocked(6);
    try {
        accel.intersect_stream(rays, hits, workspace);
        ADD_FAILURE() << "no error for 5 rays and 4 hits";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("5 rays but room for 4 hits"), std::string::npos)
            << e.what();
    }
    EXPECT_THROW(accel.occluded_stream(rays, blocked, workspace), Error);
}

TEST(TriangleAccel, NonIndexedInputAndSmallMeshes) {
    for (int count : {1, 2, 3, 4, 5, 9, 33}) {
        Mesh m = random_soup(50 + count, count);
        TriangleAccel accel;
        accel.build(m.positions, {});  // vertices 3i..3i+2, as random_soup lays them out
        for (const TestRay& r : random_rays(count, 300)) expect_same_closest(m, accel, r);
    }
}

TEST(TriangleAccel, FilterIgnoringOddPrimitivesEqualsBruteForceWithoutThem) {
    Mesh m = random_soup(21, 2500);
    TriangleAccel accel;
    accel.build(m.positions, m.indices);
    for (const TestRay& r : random_rays(22, 600)) {
        int calls = 0;
        TriangleHit hit;
        bool found =
            accel.intersect_filtered(r.o, r.d, r.tmin, r.tmax, hit, [&](const TriangleHit& c) {
                ++calls;
                // Every candidate is a real hit.
                EXPECT_EQ(triangle_t(m, c.prim, r.o, r.d), c.t);
                EXPECT_GT(c.t, r.tmin);
                EXPECT_LT(c.t, r.tmax);
                return c.prim % 2 ? HitDecision::kIgnore : HitDecision::kAccept;
            });
        BruteHit ref =
            brute_force(m, r.o, r.d, r.tmin, r.tmax, [](uint32_t p) { return p % 2 == 0; });
        ASSERT_EQ(found, ref.hit);
        if (found) {
            EXPECT_EQ(hit.t, ref.t);
            EXPECT_EQ(hit.prim % 2, 0u);
        }
        if (ref.hit) {
            EXPECT_GE(calls, 1);
        }
    }
}

TEST(Bvh, SpatialSplitsDuplicateReferencesWithinTheBudgetAndBoundTheirTriangles) {
    const Mesh m = floor_and_clutter(5, 600);
    std::vector<Aabb> boxes;
    for (const uint3 t : m.indices) {
        const float3 a = m.positions[t.x], b = m.positions[t.y], c = m.positions[t.z];
        boxes.push_back({fminf(a, fminf(b, c)), fmaxf(a, fmaxf(b, c))});
    }
    const SplitTriangles split{m.positions, m.indices};
    Bvh bvh;
    bvh.build(boxes, {}, nullptr, &split);
    size_t references = 0;
    std::vector<int> seen(m.indices.size(), 0);
    for (const BvhNode& node : bvh.nodes()) {
        if (node.count == 0) continue;
        references += node.count;
        for (uint32_t k = 0; k < node.count; ++k) ++seen[bvh.prim_order()[node.first + k]];
    }
    EXPECT_GT(references, m.indices.size()) << "no reference was split";
    EXPECT_LE(references, m.indices.size() + size_t(split.budget * m.indices.size()));
    for (int count : seen) EXPECT_GE(count, 1);  // every triangle is somewhere
}

TEST(TriangleAccel, WithoutSpatialSplitsAFilterSeesEachTriangleOnce) {
    // Spatial splits may offer a triangle twice; groups with any-hit programs build without.
    const Mesh m = floor_and_clutter(6, 800);
    BuildOptions options;
    options.spatial_splits = false;
    TriangleAccel accel;
    accel.build(m.positions, m.indices, options);
    for (const TestRay& r : random_rays(8, 500)) {
        std::vector<int> offered(m.indices.size(), 0);
        TriangleHit hit;
        accel.intersect_filtered(r.o, r.d, r.tmin, r.tmax, hit, [&](const TriangleHit& c) {
            ++offered[c.prim];
            return HitDecision::kIgnore;
        });
        for (int n : offered) ASSERT_LE(n, 1);
    }
    // With them (the default), every hit is still brute force's.
    TriangleAccel split;
    split.build(m.positions, m.indices);
    for (const TestRay& r : random_rays(9, 500)) {
        expect_same_closest(m, split, r);
        EXPECT_EQ(split.occluded(r.o, r.d, r.tmin, r.tmax),
                  brute_force(m, r.o, r.d, r.tmin, r.tmax).hit);
    }
}

TEST(TriangleAccel, AcceptAndStopEndsTheSearch) {
    Mesh m = random_soup(31, 2500);
    TriangleAccel accel;
    accel.build(m.positions, m.indices);
    for (const TestRay& r : random_rays(32, 400)) {
        int calls = 0;
        TriangleHit first{}, hit{};
        bool found =
            accel.intersect_filtered(r.o, r.d, r.tmin, r.tmax, hit, [&](const TriangleHit& c) {
                if (calls++ == 0) first = c;
                return HitDecision::kAcceptAndStop;
            });
        EXPECT_EQ(found, brute_force(m, r.o, r.d, r.tmin, r.tmax).hit);
        EXPECT_LE(calls, 1);
        if (found) {
            EXPECT_EQ(hit.prim, first.prim);
            EXPECT_EQ(hit.t, first.t);
        }
        // Accepting everything gives the plain closest hit.
        TriangleHit all, plain;
        bool a = accel.intersect_filtered(r.o, r.d, r.tmin, r.tmax, all,
                                          [](const TriangleHit&) { return HitDecision::kAccept; });
        ASSERT_EQ(a, accel.intersect(r.o, r.d, r.tmin, r.tmax, plain));
        if (a) {
            EXPECT_EQ(all.t, plain.t);
        }
    }
}

TEST(TriangleAccel, RefitEqualsFreshBuild) {
    Mesh m = random_soup(41, 2000);
    TriangleAccel refitted;
    refitted.build(m.positions, m.indices);
    std::mt19937 rng(42);
    std::uniform_real_distribution<float> jitter(-0.15f, 0.15f);
    for (float3& p : m.positions) p = p + make_float3(jitter(rng), jitter(rng) + 0.3f, jitter(rng));
    refitted.refit(m.positions, m.indices);
    TriangleAccel fresh;
    fresh.build(m.positions, m.indices);
    Aabb a = refitted.bounds(), b = fresh.bounds();
    EXPECT_EQ(a.lo.x, b.lo.x);
    EXPECT_EQ(a.hi.y, b.hi.y);
    for (TestRay r : random_rays(43, 600)) {
        r.o.y += 0.3f;
        TriangleHit h1, h2;
        bool f1 = refitted.intersect(r.o, r.d, r.tmin, r.tmax, h1);
        bool f2 = fresh.intersect(r.o, r.d, r.tmin, r.tmax, h2);
        ASSERT_EQ(f1, f2);
        if (f1) {
            EXPECT_EQ(h1.t, h2.t);
        }
        EXPECT_EQ(refitted.occluded(r.o, r.d, r.tmin, r.tmax), f2);
        expect_same_closest(m, refitted, r);
    }
}

/// A closed, finely tessellated sphere (lat-long grid) around `center`.
Mesh closed_sphere(float3 center, float radius, int rings, int segments) {
    Mesh m;
    const float pi = 3.14159265f;
    m.positions.push_back(center + make_float3(0, radius, 0));
    for (int i = 1; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            float th = pi * i / rings, ph = 2 * pi * j / segments;
            m.positions.push_back(center + radius * make_float3(std::sin(th) * std::cos(ph),
                                                                std::cos(th),
                                                                std::sin(th) * std::sin(ph)));
        }
    m.positions.push_back(center + make_float3(0, -radius, 0));
    const uint32_t south = (uint32_t)m.positions.size() - 1;
    auto ring = [&](int i, int j) { return 1 + (uint32_t)((i - 1) * segments + j % segments); };
    for (int j = 0; j < segments; ++j) {
        m.indices.push_back(make_uint3(0, ring(1, j + 1), ring(1, j)));
        m.indices.push_back(make_uint3(south, ring(rings - 1, j), ring(rings - 1, j + 1)));
    }
    for (int i = 1; i + 1 < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            m.indices.push_back(make_uint3(ring(i, j), ring(i, j + 1), ring(i + 1, j)));
            m.indices.push_back(make_uint3(ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)));
        }
    return m;
}

TEST(TriangleAccel, WatertightOnSharedEdgesAndVertices) {
    const float3 center = make_float3(0.3f, -0.2f, 0.7f);
    Mesh m = closed_sphere(center, 1.3f, 40, 64);
    TriangleAccel accel;
    accel.build(m.positions, m.indices);
    int rays = 0;
    const float3 origins[3] = {center, center + make_float3(0.11f, 0.23f, -0.31f),
                               center + make_float3(5.0f, 3.0f, -4.0f)};
    for (const float3& o : origins) {
        const bool inside = length(o - center) < 1.3f;
        for (uint3 t : m.indices) {
            const float3 p[3] = {m.positions[t.x], m.positions[t.y], m.positions[t.z]};
            // Aim at each vertex and at each edge's midpoint: points shared by triangles.
            const float3 targets[6] = {
                p[0], p[1], p[2], 0.5f * (p[0] + p[1]), 0.5f * (p[1] + p[2]), 0.5f * (p[2] + p[0])};
            for (const float3& target : targets) {
                const float3 d = target - o;
                // From outside, keep clear of the silhouette: there a ray through a vertex
                // may rightly pass beside the fold of front- and back-facing triangles.
                if (!inside && dot(normalize(d), normalize(target - center)) > -0.3f) continue;
                TriangleHit hit;
                ASSERT_TRUE(accel.intersect(o, d, 0.0f, kInfinity, hit))
                    << "ray slipped through: o " << o.x << " " << o.y << " " << o.z << " d " << d.x
                    << " " << d.y << " " << d.z;
                ASSERT_TRUE(accel.occluded(o, d, 0.0f, kInfinity));
                ++rays;
            }
        }
    }
    EXPECT_GT(rays, 40000);
}

// ---- the benchmark scenes -------------------------------------------------------------

std::filesystem::path scenes_dir() {
    return LUCENT_SCENES_DIR;
}

struct View {
    float3 eye, look, up, light;
    float fov;
};

bool find_view(const std::string& name, View& view) {
    std::ifstream in(scenes_dir() / "cameras.txt");
    std::string line;
    auto f3 = [](const std::string& s) {
        float3 v;
        std::sscanf(s.c_str(), "%f,%f,%f", &v.x, &v.y, &v.z);
        return v;
    };
    while (std::getline(in, line)) {
        std::istringstream f(line);
        std::string file, eye, look, up, light;
        float fov;
        if (!(f >> file) || file != name || !(f >> eye >> look >> up >> fov >> light)) continue;
        view = View{f3(eye), f3(look), f3(up), f3(light), fov};
        return true;
    }
    return false;
}

/// Rays per scene: LUCENT_SCENE_RAYS, else 700 (scripts/test-sanitized.sh asks for 40: each
/// ray is checked against brute force over every triangle, minutes per scene under ASan).
unsigned scene_rays() {
    const char* env = std::getenv("LUCENT_SCENE_RAYS");
    const int rays = env ? std::atoi(env) : 700;
    if (rays < 1) ADD_FAILURE() << "LUCENT_SCENE_RAYS=" << env << ": give a positive count of rays";
    return rays < 1 ? 700u : unsigned(rays);
}

void check_scene(const std::string& name) {
    const std::filesystem::path file = scenes_dir() / name;
    View view{};
    if (!std::filesystem::exists(file) || !find_view(name, view))
        GTEST_SKIP() << "no " << file << " (or its line in cameras.txt): the scene test needs "
                     << "../shared/scenes";
    scene::ObjMesh obj = scene::load_obj_mesh(file.string());
    Mesh m{obj.positions, obj.indices};
    TriangleAccel accel;
    BuildStats stats;
    accel.build(m.positions, m.indices, {}, &stats);
    EXPECT_LE(stats.depth, 60u);
    // BENCH.md primary rays on a sparse pixel grid, and shadow + diffuse rays from the hits.
    const unsigned w = 1024, h = 768;
    const float3 fwd = normalize(view.look - view.eye);
    const float3 right = normalize(cross(fwd, view.up)), up2 = cross(right, fwd);
    const float tf = std::tan(view.fov / 2 * 3.14159265f / 180), a = (float)w / h;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    int hits = 0;
    const unsigned rays = scene_rays();
    const unsigned step = std::max(w * h / rays, 1u);  // spans the image (1123 pixels for 700 rays)
    for (unsigned i = 0; i < rays; ++i) {
        unsigned pixel = (i * step) % (w * h), x = pixel % w, y = pixel / w;
        float u = (2 * (x + 0.5f) / w - 1) * tf * a, v = (1 - 2 * (y + 0.5f) / h) * tf;
        TestRay r{view.eye, normalize(fwd + u * right + v * up2), 0.0f, kInfinity};
        expect_same_closest(m, accel, r);
        TriangleHit hit;
        if (!accel.intersect(r.o, r.d, 0.0f, kInfinity, hit)) continue;
        ++hits;
        uint3 t = m.indices[hit.prim];
        float3 n = normalize(
            cross(m.positions[t.y] - m.positions[t.x], m.positions[t.z] - m.positions[t.x]));
        if (dot(n, r.d) > 0) n = -n;
        float3 o = r.o + hit.t * r.d + 1e-3f * n;
        float3 to_light = view.light - o;
        float dist = length(to_light);
        EXPECT_EQ(accel.occluded(o, to_light / dist, 0.0f, dist),
                  brute_force(m, o, to_light / dist, 0.0f, dist).hit);
        float3 d = normalize(n + make_float3(uni(rng), uni(rng), uni(rng)) * 0.9f);
        expect_same_closest(m, accel, TestRay{o, d, 0.0f, kInfinity});
    }
    EXPECT_GT(hits, int(rays / 7));  // 100 of 700: a seventh of the primary rays hit, at least
}

TEST(TriangleAccelScenes, BunnyEqualsBruteForce) {
    check_scene("bunny.obj");
}
TEST(TriangleAccelScenes, SponzaEqualsBruteForce) {
    check_scene("sponza.obj");
}

// ---- the traversal's instruction-set variants (cpu_isa.h) -------------------------------

/// The variant LUCENT_CPU_ISA asks for, if any.
std::optional<CpuIsa> requested_isa() {
    const char* env = std::getenv("LUCENT_CPU_ISA");
    return env ? parse_cpu_isa(env) : std::nullopt;
}

/// A run for a variant this CPU lacks would test another one under its name, so it ends
/// before the tests with 77, which ctest reports as skipped (SKIP_RETURN_CODE).
struct SkipUnsupportedIsa : ::testing::Environment {
    void SetUp() override {
        const std::optional<CpuIsa> isa = requested_isa();
        if (!isa || cpu_isa_supported(*isa)) return;
        std::printf("LUCENT_CPU_ISA=%s: this build or this CPU lacks it, skipped\n",
                    cpu_isa_name(*isa));
        std::fflush(stdout);
        std::exit(77);
    }
};
[[maybe_unused]] ::testing::Environment* const skip_unsupported_isa =
    ::testing::AddGlobalTestEnvironment(new SkipUnsupportedIsa);

TEST(CpuIsa, TheRequestedVariantRunsOrElseTheBest) {
    CpuIsa best = CpuIsa::kScalar;
    for (CpuIsa isa : kCpuIsas)
        if (cpu_isa_supported(isa)) best = isa;
    const CpuIsa expected = requested_isa().value_or(best);
    EXPECT_STREQ(cpu_isa_name(active_cpu_isa()), cpu_isa_name(expected));
}

TEST(CpuIsa, EachVariantHasTheCodePathsItsNameSays) {
    // What the variant's compile flags let triangle_traverse.cpp's #if's enable.
    const char* expected[] = {"scalar", "avx2 fma", "avx2 fma avx512vl"};
    for (CpuIsa isa : kCpuIsas)
        if (cpu_isa_supported(isa))
            EXPECT_STREQ(traverse_variant(isa).paths, expected[int(isa)]) << cpu_isa_name(isa);
}

TEST(CpuIsa, NamesRoundTrip) {
    for (CpuIsa isa : kCpuIsas) EXPECT_EQ(parse_cpu_isa(cpu_isa_name(isa)), isa);
    EXPECT_FALSE(parse_cpu_isa("sse4"));
    EXPECT_FALSE(parse_cpu_isa(""));
}

// ---- the OBJ loader -------------------------------------------------------------------

std::string write_temp(const std::string& name, const std::string& text) {
    std::filesystem::path p = std::filesystem::temp_directory_path() / ("lucent_accel_" + name);
    std::ofstream(p) << text;
    return p.string();
}

std::string load_error(const std::string& path) {
    try {
        scene::load_obj_mesh(path);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(ObjMesh, LoadsAndFansPolygons) {
    std::string path = write_temp("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    scene::ObjMesh mesh = scene::load_obj_mesh(path);
    ASSERT_EQ(mesh.positions.size(), 4u);
    ASSERT_EQ(mesh.indices.size(), 2u);
    EXPECT_EQ(mesh.indices[1].x, 0u);
    EXPECT_EQ(mesh.indices[1].z, 3u);
}

TEST(ObjMesh, ErrorsNameFileAndLine) {
    std::string missing = (std::filesystem::temp_directory_path() / "lucent_no_such.obj").string();
    EXPECT_NE(load_error(missing).find(missing + ":"), std::string::npos);
    std::string nan = write_temp("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
    EXPECT_NE(load_error(nan).find(nan + ":3:"), std::string::npos) << load_error(nan);
    std::string range = write_temp("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n# c\nf 1 2 9\n");
    EXPECT_NE(load_error(range).find(range + ":5:"), std::string::npos) << load_error(range);
    std::string empty = write_temp("empty.obj", "v 0 0 0\nv 1 0 0\n");
    EXPECT_NE(load_error(empty).find("no triangles"), std::string::npos) << load_error(empty);
}

}  // namespace
}  // namespace lucent::accel

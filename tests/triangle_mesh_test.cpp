// scene::TriangleMesh (scene/triangle_mesh.h), the ray queries of the C++ package and of
// Python's lucent.TriangleMesh: the CPU's direct queries against the BVH's single-ray
// answers, the engine's path (a Context launching the query module) against the direct one,
// the rays that are not rays, updates, a built-in scene, and misuse.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "accel/triangle_accel.h"
#include "lucent/error.h"
#include "scene/triangle_mesh.h"

namespace lucent::scene {
namespace {

struct Soup {
    std::vector<float3> vertices;
    std::vector<uint3> triangles;
};

/// Triangles between random points of the cube [-1, 1]^3, sharing vertices.
Soup random_soup(std::mt19937& rng, unsigned vertex_count = 300, unsigned triangle_count = 400) {
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::uniform_int_distribution<unsigned> pick(0, vertex_count - 1);
    Soup s;
    for (unsigned i = 0; i < vertex_count; ++i)
        s.vertices.push_back(make_float3(u(rng), u(rng), u(rng)));
    while (s.triangles.size() < triangle_count) {
        const uint3 t = make_uint3(pick(rng), pick(rng), pick(rng));
        if (t.x != t.y && t.y != t.z && t.x != t.z) s.triangles.push_back(t);
    }
    return s;
}

struct Rays {
    std::vector<float3> origins, directions;
    std::vector<float> tmin, tmax;
    MeshRays view() const { return MeshRays{origins, directions, tmin, tmax}; }
};

/// Rays from a sphere of radius 3 towards points of the cube, some pointing away, of random
/// lengths, with per-ray intervals: most (0, inf), some cut short.
Rays random_rays(std::mt19937& rng, unsigned count) {
    std::normal_distribution<float> g;
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), len(0.2f, 3.0f), p(0.0f, 1.0f);
    Rays r;
    for (unsigned i = 0; i < count; ++i) {
        float3 o = make_float3(g(rng), g(rng), g(rng));
        o = o * (3.0f / length(o));
        float3 d = (make_float3(u(rng), u(rng), u(rng)) - o) * len(rng);
        if (p(rng) < 0.15f) d = -d;
        r.origins.push_back(o);
        r.directions.push_back(d);
        r.tmin.push_back(p(rng) < 0.2f ? p(rng) * 0.5f : 0.0f);
        r.tmax.push_back(p(rng) < 0.2f ? 0.3f + p(rng) : kInfinity);
    }
    return r;
}

struct Answers {
    std::vector<float> t;
    std::vector<int32_t> prim;
    std::vector<float2> uv;
    std::vector<float3> normal;
    std::vector<uint8_t> blocked;
    explicit Answers(size_t n) : t(n), prim(n), uv(n), normal(n), blocked(n) {}
    MeshHits hits() { return MeshHits{t, prim, uv, normal}; }
};

Answers answer(TriangleMesh& mesh, const Rays& rays) {
    Answers a(rays.origins.size());
    mesh.intersect(rays.view(), a.hits());
    mesh.occluded(rays.view(), a.blocked);
    return a;
}

ContextOptions cpu_options(unsigned threads = 2) {
    ContextOptions options;
    options.backend = BackendKind::kCpu;
    options.threads = threads;
    return options;
}

TEST(TriangleMesh, CpuQueriesGiveTheBvhsSingleRayAnswers) {
    std::mt19937 rng(7);
    const Soup soup = random_soup(rng);
    const Rays rays = random_rays(rng, 5000);
    TriangleMesh mesh(soup.vertices, soup.triangles, cpu_options());
    EXPECT_EQ(mesh.vertex_count(), soup.vertices.size());
    EXPECT_EQ(mesh.triangle_count(), soup.triangles.size());
    EXPECT_EQ(mesh.backend_name().rfind("cpu", 0), 0u) << mesh.backend_name();
    const Answers a = answer(mesh, rays);

    accel::TriangleAccel bvh;
    bvh.build(soup.vertices, soup.triangles);
    unsigned hits = 0, blocked = 0;
    for (size_t i = 0; i < rays.origins.size(); ++i) {
        accel::TriangleHit h;
        const float3 o = rays.origins[i], d = rays.directions[i];
        const bool hit = bvh.intersect(o, d, rays.tmin[i], rays.tmax[i], h);
        ASSERT_EQ(a.prim[i] >= 0, hit) << "ray " << i;
        ASSERT_EQ(bool(a.blocked[i]), bvh.occluded(o, d, rays.tmin[i], rays.tmax[i]))
            << "ray " << i;
        blocked += a.blocked[i];
        if (!hit) {
            EXPECT_TRUE(std::isinf(a.t[i]) && a.t[i] > 0) << "ray " << i;
            continue;
        }
        ++hits;
        EXPECT_EQ(a.t[i], h.t) << "ray " << i;        // the same watertight test, bit for bit
        if (uint32_t(a.prim[i]) != h.prim) continue;  // a tie: two triangles at the same t
        EXPECT_EQ(a.uv[i].x, h.u) << "ray " << i;
        EXPECT_EQ(a.uv[i].y, h.v) << "ray " << i;
        // The geometric normal: unit length, along the triangle's winding-order normal.
        const uint3 tri = soup.triangles[h.prim];
        const float3 p0 = soup.vertices[tri.x], p1 = soup.vertices[tri.y],
                     p2 = soup.vertices[tri.z];
        const float3 n = normalize(cross(p1 - p0, p2 - p0));
        EXPECT_NEAR(length(a.normal[i]), 1.0f, 1e-5f) << "ray " << i;
        EXPECT_GT(dot(a.normal[i], n), 0.9999f) << "ray " << i;
    }
    // The rays are made so that both answers are common.
    EXPECT_GT(hits, 1500u);
    EXPECT_LT(hits, 4900u);
    EXPECT_GT(blocked, 1500u);
}

// The engine's path: a Context launching the query module (mesh_query_programs.h), taken on
// the CPU when a device list is given. Its answers are the direct queries', bit for bit.
TEST(TriangleMesh, TheEnginesPathAnswersAsTheDirectQueries) {
    std::mt19937 rng(11);
    const Soup soup = random_soup(rng, 200, 300);
    Rays rays = random_rays(rng, 3000);
    TriangleMesh direct(soup.vertices, soup.triangles, cpu_options());
    ContextOptions through_engine = cpu_options();
    through_engine.devices = {DeviceSpec{DeviceSpec::Kind::kCpu, 0}};
    TriangleMesh engine(soup.vertices, soup.triangles, through_engine);
    const Answers a = answer(direct, rays), b = answer(engine, rays);
    // The engine's launch ran every ray on the listed device; the direct queries launch none.
    ASSERT_EQ(engine.last_launch().devices.size(), 1u);
    EXPECT_EQ(engine.last_launch().devices[0].indices, rays.origins.size());
    EXPECT_TRUE(direct.last_launch().devices.empty());
    for (size_t i = 0; i < rays.origins.size(); ++i) {
        ASSERT_EQ(a.t[i], b.t[i]) << "ray " << i;
        ASSERT_EQ(a.blocked[i], b.blocked[i]) << "ray " << i;
        if (a.prim[i] != b.prim[i]) continue;  // a tie, met in another order
        EXPECT_EQ(a.uv[i].x, b.uv[i].x) << "ray " << i;
        EXPECT_EQ(a.normal[i].z, b.normal[i].z) << "ray " << i;
    }
    // One tmin and tmax for every ray, and none (0 and no bound), the same on both paths.
    for (const auto& [tmin, tmax] : {std::pair{std::vector<float>{0.25f}, std::vector<float>{2.5f}},
                                     std::pair{std::vector<float>{}, std::vector<float>{}}}) {
        rays.tmin = tmin, rays.tmax = tmax;
        const Answers c = answer(direct, rays), e = answer(engine, rays);
        EXPECT_EQ(c.t, e.t);
        EXPECT_EQ(c.blocked, e.blocked);
    }
}

TEST(TriangleMesh, RaysThatAreNotRaysAreMisses) {
    const std::vector<float3> v = {make_float3(-1, -1, 0), make_float3(1, -1, 0),
                                   make_float3(0, 1, 0)};
    const std::vector<uint3> tri = {make_uint3(0, 1, 2)};
    TriangleMesh mesh(v, tri, cpu_options(1));
    const float nan = std::nanf("");
    Rays rays;
    rays.origins = {make_float3(0, 0, 1), make_float3(nan, 0, 1), make_float3(0, 0, 1),
                    make_float3(0, 0, 1), make_float3(0, 0, kInfinity)};
    rays.directions = {make_float3(0, 0, -1), make_float3(0, 0, -1), make_float3(0, 0, 0),
                       make_float3(0, 0, -1), make_float3(0, 0, -1)};
    rays.tmin = {0, 0, 0, nan, 0};
    const Answers a = answer(mesh, rays);
    EXPECT_EQ(a.t[0], 1.0f);
    EXPECT_EQ(a.prim[0], 0);
    EXPECT_EQ(a.blocked[0], 1);
    EXPECT_NEAR(a.normal[0].z, 1.0f, 1e-6f);
    for (size_t i = 1; i < rays.origins.size(); ++i) {
        EXPECT_EQ(a.prim[i], -1) << "ray " << i;
        EXPECT_EQ(a.blocked[i], 0) << "ray " << i;
    }
}

TEST(TriangleMesh, UpdatesRefitOrRebuildTheBvh) {
    std::vector<float3> v = {make_float3(-1, -1, 0), make_float3(1, -1, 0), make_float3(0, 1, 0)};
    const std::vector<uint3> tri = {make_uint3(0, 1, 2)};
    TriangleMesh mesh(v, tri, cpu_options(1));
    Rays rays;
    rays.origins = {make_float3(0, 0, 5)};
    rays.directions = {make_float3(0, 0, -1)};
    EXPECT_EQ(answer(mesh, rays).t[0], 5.0f);
    for (bool rebuild : {false, true}) {
        for (float3& p : v) p.z += 1.0f;  // the triangle moves towards the ray's origin
        mesh.update(v, rebuild);
        Answers a(1);
        mesh.intersect(rays.view(), a.hits());
        EXPECT_TRUE(mesh.last_launch().recompiled);  // the refit or the rebuild, at this query
        EXPECT_EQ(a.t[0], rebuild ? 3.0f : 4.0f);
        mesh.occluded(rays.view(), a.blocked);
        EXPECT_FALSE(mesh.last_launch().recompiled);  // nothing moved since
        EXPECT_EQ(a.blocked[0], 1);
    }
}

TEST(TriangleMesh, LoadsABuiltInSceneJoinedWhereItIsDrawn) {
    TriangleMesh cornell = TriangleMesh::load("cornell", cpu_options());
    EXPECT_GT(cornell.triangle_count(), 10u);
    // Straight down from the middle of the box: the floor, at y = 0.
    Rays rays;
    rays.origins = {make_float3(278, 274, 280)};
    rays.directions = {make_float3(0, -1, 0)};
    const Answers a = answer(cornell, rays);
    ASSERT_GE(a.prim[0], 0);
    EXPECT_NEAR(a.t[0], 274.0f, 1.0f);
    EXPECT_GT(a.normal[0].y, 0.99f);
    EXPECT_THROW(TriangleMesh::load("no-such-mesh.obj", cpu_options()), Error);
}

/// The message of the lucent::Error `call` throws ("" when it throws none).
template <class Call>
std::string error_of(Call call) {
    try {
        call();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(TriangleMesh, MisuseIsAnErrorNamingTheArgumentAndTheFix) {
    const std::vector<float3> v = {make_float3(-1, -1, 0), make_float3(1, -1, 0),
                                   make_float3(0, 1, 0)};
    const std::vector<uint3> bad = {make_uint3(0, 1, 2), make_uint3(0, 1, 3)};
    std::string e = error_of([&] { TriangleMesh(v, bad, cpu_options()); });
    EXPECT_NE(e.find("triangle 1 is (0, 1, 3)"), std::string::npos) << e;
    EXPECT_NE(e.find("below 3"), std::string::npos) << e;
    e = error_of([&] { TriangleMesh({}, {}, cpu_options()); });
    EXPECT_NE(e.find("no vertices"), std::string::npos) << e;

    TriangleMesh mesh(v, std::vector<uint3>{make_uint3(0, 1, 2)}, cpu_options(1));
    Rays rays;
    rays.origins = {make_float3(0, 0, 1), make_float3(0, 0, 2)};
    rays.directions = {make_float3(0, 0, -1)};
    Answers a(2);
    e = error_of([&] { mesh.intersect(rays.view(), a.hits()); });
    EXPECT_NE(e.find("TriangleMesh::intersect: directions has 1 entries for 2 rays"),
              std::string::npos)
        << e;
    rays.directions.push_back(make_float3(0, 0, -1));
    rays.tmax = {1, 2, 3};
    e = error_of([&] { mesh.occluded(rays.view(), a.blocked); });
    EXPECT_NE(e.find("tmax has 3 entries for 2 rays; give one per ray, one for every ray, or none"),
              std::string::npos)
        << e;
    rays.tmax.clear();
    a.uv.resize(1);
    e = error_of([&] { mesh.intersect(rays.view(), a.hits()); });
    EXPECT_NE(e.find("out.uv has 1 entries for 2 rays"), std::string::npos) << e;
    std::vector<uint8_t> blocked(3);
    e = error_of([&] { mesh.occluded(rays.view(), blocked); });
    EXPECT_NE(e.find("blocked has 3 entries"), std::string::npos) << e;
    e = error_of([&] { mesh.update(std::vector<float3>(4), false); });
    EXPECT_NE(e.find("4 vertices for a mesh of 3"), std::string::npos) << e;

    TriangleMesh moved_to = std::move(mesh);
    e = error_of([&] { mesh.occluded(rays.view(), std::span<uint8_t>(blocked).first(2)); });
    EXPECT_NE(e.find("moved from"), std::string::npos) << e;
    EXPECT_EQ(
        error_of([&] { moved_to.occluded(rays.view(), std::span<uint8_t>(blocked).first(2)); }),
        "");
    EXPECT_EQ(blocked[0], 1);
    EXPECT_EQ(blocked[1], 1);
}

}  // namespace
}  // namespace lucent::scene

// The host's form of a GeometryGroup's triangles (core/triangle_gather.h): the gathered mesh
// the CPU's BVH is built over, and the bounds a GPU build's compile computes instead of
// gathering (the GPU gathers on the device: gpu_bvh_builder_test's GatherMakesTheHostsMesh).
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "core/triangle_gather.h"
#include "lucent/lucent.h"

namespace lucent {
namespace {

/// Instances of triangles for a hand-made compiled scene: the nodes and buffers stay alive
/// as long as the scene that points into them.
struct GatherScene {
    Context ctx{ContextOptions{.backend = BackendKind::kCpu}};
    std::vector<std::shared_ptr<GeometryInstance>> instances;
    core::CompiledScene scene;
    core::CompiledNode node;

    /// Adds an instance of `positions` (and `indices`, or none: unindexed triangles).
    void add(const std::vector<float3>& positions, const std::vector<uint3>& indices) {
        auto vertices = ctx.create_buffer<float3>(BufferType::kInput, unsigned(positions.size()));
        vertices->upload(positions);
        auto triangles = ctx.create_geometry_triangles();
        triangles->set_vertices(vertices);
        std::shared_ptr<Buffer> index_buffer;
        if (!indices.empty()) {
            index_buffer = ctx.create_buffer<uint3>(BufferType::kInput, unsigned(indices.size()));
            index_buffer->upload(indices);
            triangles->set_indices(index_buffer);
        }
        auto instance = ctx.create_geometry_instance();
        instance->set_geometry(triangles);
        instances.push_back(instance);
        core::CompiledInstance c;
        c.source = instance.get();
        c.type = PrimitiveType::kTriangles;
        c.primitive_count = unsigned(indices.empty() ? positions.size() / 3 : indices.size());
        c.vertices = vertices->data<float3>();
        c.indices = index_buffer ? static_cast<const uint3*>(index_buffer->raw()) : nullptr;
        node.instances.push_back(unsigned(scene.instances.size()));
        scene.instances.push_back(c);
    }
};

std::vector<float3> points(std::initializer_list<float> xyz) {
    std::vector<float3> out;
    for (auto it = xyz.begin(); it != xyz.end(); it += 3) out.push_back({it[0], it[1], it[2]});
    return out;
}

TEST(TriangleGather, ConcatenatesVerticesAndRebasesIndices) {
    GatherScene g;
    g.add(points({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}), {{0, 1, 2}, {2, 1, 3}});
    g.add(points({5, 5, 5, 6, 5, 5, 5, 6, 5}), {});  // unindexed: one triangle
    g.add(points({-1, 0, 0, 0, -1, 0, 0, 0, -1}), {{2, 1, 0}});
    std::vector<float3> vertices;
    std::vector<uint3> indices;
    std::vector<uint32_t> tri_instance;
    core::gather_triangles(g.scene, g.node, vertices, indices, &tri_instance);
    ASSERT_EQ(vertices.size(), 10u);
    EXPECT_EQ(vertices[4].x, 5.0f);
    EXPECT_EQ(vertices[9].z, -1.0f);
    const std::vector<uint3> want = {{0, 1, 2}, {2, 1, 3}, {4, 5, 6}, {9, 8, 7}};
    ASSERT_EQ(indices.size(), want.size());
    for (size_t i = 0; i < want.size(); ++i) {
        EXPECT_EQ(indices[i].x, want[i].x) << i;
        EXPECT_EQ(indices[i].y, want[i].y) << i;
        EXPECT_EQ(indices[i].z, want[i].z) << i;
    }
    EXPECT_EQ(tri_instance, (std::vector<uint32_t>{0, 0, 1, 2}));
}

TEST(TriangleGather, BoundsHoldEveryTriangleAndOnlyWhatTheBufferHolds) {
    GatherScene g;
    // A compact buffer: its box is the triangles'.
    g.add(points({0, 0, 0, 1, 0, 0, 0, 2, 0, 1, 1, 3}), {{0, 1, 2}, {2, 1, 3}});
    // A buffer of 9 vertices of which one triangle uses 3 (more vertices than 3 per
    // triangle): the box comes through the indices and leaves the far vertices out.
    g.add(points({100, 100, 100, 0, 0, -4, 0, 0,   0, 0, 0, 0, 0, 0,
                  0,   0,   0,   0, 0, 0,  0, -50, 0, 0, 7, 0, 0}),
          {{1, 2, 8}});
    const Aabb box = core::triangle_bounds(g.scene, g.node);
    EXPECT_EQ(box.lo.x, 0.0f);
    EXPECT_EQ(box.lo.y, 0.0f);
    EXPECT_EQ(box.lo.z, -4.0f);
    EXPECT_EQ(box.hi.x, 7.0f);
    EXPECT_EQ(box.hi.y, 2.0f);
    EXPECT_EQ(box.hi.z, 3.0f);
}

TEST(TriangleGather, BoundsOfLongBuffersFindEachAxisExtremeWhereverItIs) {
    // Buffers long enough for the bounds' 16-point steps and a tail: each axis's extreme is
    // planted at a different point (in a step's first, middle or last point, or in the
    // tail), so a running minimum kept for the wrong axis, a skipped step or tail shows.
    for (const unsigned count : {16u, 17u, 48u, 100u, 1003u}) {
        std::vector<float3> v(count);
        for (unsigned i = 0; i < count; ++i)
            v[i] = {float(i % 7) - 3.0f, float(i % 11) * 0.5f, float(i % 5) + 10.0f};
        const unsigned at[6] = {0, count / 2, count - 1, count / 3, 15 % count, count - 2};
        v[at[0]].x = -1e3f, v[at[1]].y = -2e3f, v[at[2]].z = -3e3f;
        v[at[3]].x = 4e3f, v[at[4]].y = 5e3f, v[at[5]].z = 6e3f;
        std::vector<uint3> indices;  // as many indices as vertices: the buffer is read whole
        for (unsigned i = 0; i + 2 < count; i += 3) indices.push_back({i, i + 1, i + 2});
        indices.push_back({count - 3, count - 2, count - 1});
        GatherScene g;
        g.add(v, indices);
        const Aabb box = core::triangle_bounds(g.scene, g.node);
        EXPECT_EQ(box.lo.x, -1e3f) << count;
        EXPECT_EQ(box.lo.y, -2e3f) << count;
        EXPECT_EQ(box.lo.z, -3e3f) << count;
        EXPECT_EQ(box.hi.x, 4e3f) << count;
        EXPECT_EQ(box.hi.y, 5e3f) << count;
        EXPECT_EQ(box.hi.z, 6e3f) << count;
    }
}

TEST(TriangleGather, NoTrianglesGiveAnEmptyBox) {
    GatherScene g;
    g.add({}, {});
    const Aabb box = core::triangle_bounds(g.scene, g.node);
    EXPECT_GT(box.lo.x, box.hi.x);
}

}  // namespace
}  // namespace lucent

// RayStreamWorkspace: the buffers of the stream queries (ray_stream.h), grown on demand and
// kept between calls.
#include "accel/ray_stream.h"

#include <algorithm>

namespace lucent::accel {

struct RayStreamWorkspace::Storage {
    size_t rays = 0;
    unsigned depth = 0;
    // Plain new[]: the streams' buffer is sized for the deepest walk, and only the pages a
    // batch writes are ever touched, so it must not be cleared up front.
    std::unique_ptr<StreamNodeRay[]> node_rays;
    std::unique_ptr<StreamLeafRay[]> leaf_rays;
    std::unique_ptr<uint32_t[]> prim;
    std::unique_ptr<float[]> e1, e2, det;
    std::unique_ptr<uint32_t[]> ids;
    std::unique_ptr<StreamEntry[]> stack;
    StreamBuffers buffers;
};

RayStreamWorkspace::RayStreamWorkspace() : m_storage(std::make_unique<Storage>()) {}
RayStreamWorkspace::~RayStreamWorkspace() = default;
RayStreamWorkspace::RayStreamWorkspace(RayStreamWorkspace&&) noexcept = default;
RayStreamWorkspace& RayStreamWorkspace::operator=(RayStreamWorkspace&&) noexcept = default;

StreamBuffers& RayStreamWorkspace::reserve(size_t rays, unsigned depth) {
    if (!m_storage) m_storage = std::make_unique<Storage>();
    Storage& s = *m_storage;
    depth = std::max(depth, 1u);
    if (rays <= s.rays && depth <= s.depth) return s.buffers;
    s.rays = std::max(rays, s.rays);
    s.depth = std::max(depth, s.depth);
    // Sixteen slots past the last ray: the queries read and write whole 16-lane vectors.
    const size_t slots = s.rays + 16;
    s.node_rays.reset(new StreamNodeRay[slots]);
    s.leaf_rays.reset(new StreamLeafRay[slots]);
    s.prim.reset(new uint32_t[slots]);
    s.e1.reset(new float[slots]);
    s.e2.reset(new float[slots]);
    s.det.reset(new float[slots]);
    // A node's stream holds at most the batch's rays, and it lays out eight children's
    // streams of up to its own size (plus a vector's overhang, rounded to sixteen) above
    // where its parent's end: (8 * depth + 1) * (rays + 32) bounds the deepest walk.
    s.buffers.id_capacity = (8 * size_t(s.depth) + 1) * (s.rays + 32);
    s.ids.reset(new uint32_t[s.buffers.id_capacity]);
    // A node pushes at most eight children, and one of them is popped before the next push.
    s.buffers.stack_capacity = 8 * size_t(s.depth) + 1;
    s.stack.reset(new StreamEntry[s.buffers.stack_capacity]);
    s.buffers.node_rays = s.node_rays.get();
    s.buffers.leaf_rays = s.leaf_rays.get();
    s.buffers.prim = s.prim.get();
    s.buffers.e1 = s.e1.get();
    s.buffers.e2 = s.e2.get();
    s.buffers.det = s.det.get();
    s.buffers.ids = s.ids.get();
    s.buffers.stack = s.stack.get();
    return s.buffers;
}

}  // namespace lucent::accel

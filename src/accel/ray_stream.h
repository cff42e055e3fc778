// Ray streams: many rays traced through TriangleAccel's tree together, node by node,
// instead of one ray's walk after another's (Barringer and Akenine-Möller 2014, "Dynamic
// ray stream traversal"). A node is tested against sixteen rays of the stream per
// instruction, the rays that hit a child go on to it as the child's stream, and a leaf's
// triangles are tested against its whole stream. A node's and a leaf's memory is then read
// once for all the rays that reach it, where single rays each wait on it: for incoherent
// (diffuse) rays on the CPU that wait is most of a ray's time (docs/performance.md,
// sessions 34 and 37).
//
// What the queries and their callers share: the rays, the answers, and the memory the
// stream works in (RayStreamWorkspace), which a thread keeps between calls.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "lucent/device/vector_math.h"

namespace lucent::accel {

/// One ray of a stream: hits count with t in (tmin, tmax), as in TriangleAccel::intersect.
struct StreamRay {
    float3 origin;
    float tmin;
    float3 direction;
    float tmax;
};

/// A stream query's answer for one ray. prim is kStreamMiss when nothing was hit; t, u and
/// v are then undefined.
struct StreamHit {
    float t;
    float u, v;     // barycentrics of vertices 1 and 2, as TriangleHit's
    uint32_t prim;  // the triangle's index in the input order
};
constexpr uint32_t kStreamMiss = 0xffffffffu;

/// The rays of one batch as the stream's node test reads them: sixteen rays' fields are
/// gathered at once, so a ray's fields share one 32-byte record.
struct alignas(32) StreamNodeRay {
    float ox, oy, oz, tmax;  // tmax shrinks as hits are found; -inf once an occlusion ray is blocked
    float rx, ry, rz, tmin;  // 1/d, clamped as the single-ray test clamps it
};
/// The same rays as the watertight triangle test reads them (Woop, Benthin and Wald 2013):
/// the origin in the ray's permuted axes, the shear, and the axes packed kx | ky << 2 | kz << 4.
struct alignas(32) StreamLeafRay {
    float ox, oy, oz;
    int32_t axes;
    float sx, sy, sz;
    float unused;
};

/// A node or leaf still to visit, and where its stream (ray indices into the batch) lies.
struct StreamEntry {
    uint32_t ref;        // as WideNode::child
    uint32_t begin;      // its ray indices: ids[begin, begin + count)
    uint32_t count;
    uint32_t next_free;  // where the streams of its children may start
};

/// The buffers of one batch, sized by RayStreamWorkspace::reserve before a query.
struct StreamBuffers {
    StreamNodeRay* node_rays = nullptr;
    StreamLeafRay* leaf_rays = nullptr;
    // The best hit so far of each ray of the batch (closest hit), or whether it is blocked.
    uint32_t* prim = nullptr;
    float *e1 = nullptr, *e2 = nullptr, *det = nullptr;
    uint32_t* ids = nullptr;  // the streams: the batch's first, then the children's
    size_t id_capacity = 0;
    StreamEntry* stack = nullptr;
    size_t stack_capacity = 0;
};

/// The memory of a thread's stream queries. Keep one per thread and pass it to every call:
/// a batch then allocates nothing. Not to be shared between threads at once.
class RayStreamWorkspace {
  public:
    RayStreamWorkspace();
    ~RayStreamWorkspace();
    RayStreamWorkspace(RayStreamWorkspace&&) noexcept;
    RayStreamWorkspace& operator=(RayStreamWorkspace&&) noexcept;

    /// Buffers for batches of up to `rays` rays through a tree of `depth` levels of nodes.
    StreamBuffers& reserve(size_t rays, unsigned depth);

  private:
    struct Storage;
    std::unique_ptr<Storage> m_storage;
};

/// The rays of one batch a query takes at most: large enough that the nodes near the
/// leaves still see many rays each, small enough that the batch's records (64 bytes a ray)
/// and streams stay near the core. On Sponza's diffuse rays, one thread: 16K rays a batch
/// 1.29x Embree, 32K-128K 1.5-1.8x, 256K and more under 1.0x (the records no longer in
/// cache).
constexpr size_t kStreamBatch = 65536;

}  // namespace lucent::accel

// `lucent bench rays`' stream engine: the ray sets through TriangleAccel's stream queries
// (src/accel/ray_stream.h), called as a wavefront renderer would call them: each thread
// takes batches of rays from a shared counter and traces each batch as one stream, in a
// workspace it keeps from pass to pass.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "accel/triangle_accel.h"
#include "bench/rays/ray_sets.h"

namespace lucent::bench {

/// The rays of a set as stream rays (tmin 0, as the kernels' passes trace them).
std::vector<accel::StreamRay> stream_rays(const RaySet& set);

class StreamPasses {
  public:
    StreamPasses(const accel::TriangleAccel& accel, unsigned threads);

    /// Seconds of one closest-hit pass over `rays`; hits[i] is ray i's answer.
    double closest(std::span<const accel::StreamRay> rays, std::span<accel::StreamHit> hits);
    /// Seconds of one occlusion pass over `rays`; blocked[i] is ray i's answer.
    double occluded(std::span<const accel::StreamRay> rays, std::span<uint8_t> blocked);

  private:
    template <class Trace>
    double run(size_t count, const Trace& trace);

    const accel::TriangleAccel& m_accel;
    unsigned m_threads;
    std::vector<accel::RayStreamWorkspace> m_workspaces;  // one per thread
};

}  // namespace lucent::bench

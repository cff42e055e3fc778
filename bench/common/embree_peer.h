// Embree 3 as the benchmark peer: the same triangles, the same rays, in the same process.
// Built only when CMake found Embree (LUCENT_HAVE_EMBREE); otherwise available() is false.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "lucent/device/vector_math.h"

namespace lucent::bench {

class EmbreePeer {
  public:
    /// True when this build links Embree.
    static bool available();
    /// Builds an Embree scene (RTC_BUILD_QUALITY_HIGH) over the triangles; throws
    /// lucent::Error when Embree is not built in or fails.
    EmbreePeer(std::span<const float3> positions, std::span<const uint3> indices, unsigned threads);
    ~EmbreePeer();
    EmbreePeer(const EmbreePeer&) = delete;
    EmbreePeer& operator=(const EmbreePeer&) = delete;

    /// Wall time of the last build (rtcCommitScene), in milliseconds.
    double build_ms() const;
    /// Rebuilds the scene from scratch and returns the build time in milliseconds.
    double rebuild();
    /// Closest hit (rtcIntersect1) with t in [tmin, tmax]; writes t and the primitive.
    bool intersect(float3 origin, float3 direction, float tmin, float tmax, float& t,
                   uint32_t& prim) const;
    /// Any hit (rtcOccluded1) with t in [tmin, tmax].
    bool occluded(float3 origin, float3 direction, float tmin, float tmax) const;

    struct Impl;

  private:
    std::unique_ptr<Impl> m_impl;
};

}  // namespace lucent::bench

// EmbreePeer: one Embree device and scene per peer, single-ray queries (rtcIntersect1,
// rtcOccluded1) as in the peer figures of shared/BENCH.md.
#include "bench/common/embree_peer.h"

#include <chrono>
#include <cstring>
#include <string>
#include <vector>

#include "lucent/error.h"

#if LUCENT_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

namespace lucent::bench {

#if LUCENT_HAVE_EMBREE

struct EmbreePeer::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<float3> positions;
    std::vector<uint3> indices;
    double build_ms = 0.0;

    void build() {
        if (scene) rtcReleaseScene(scene);
        auto start = std::chrono::steady_clock::now();
        scene = rtcNewScene(device);
        rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
        RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        // Embree's own buffers carry the padding its SIMD loads need.
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                              RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                              positions.size()));
        std::memcpy(v, positions.data(), positions.size() * sizeof(float3));
        auto* idx = static_cast<unsigned*>(
            rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                    3 * sizeof(unsigned), indices.size()));
        std::memcpy(idx, indices.data(), indices.size() * sizeof(uint3));
        rtcCommitGeometry(geom);
        rtcAttachGeometry(scene, geom);
        rtcReleaseGeometry(geom);
        rtcCommitScene(scene);
        build_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        if (rtcGetDeviceError(device) != RTC_ERROR_NONE)
            throw Error("embree: building the peer scene failed");
    }
};

bool EmbreePeer::available() {
    return true;
}

EmbreePeer::EmbreePeer(std::span<const float3> positions, std::span<const uint3> indices,
                       unsigned threads)
    : m_impl(std::make_unique<Impl>()) {
    std::string config = threads > 0 ? "threads=" + std::to_string(threads) : "";
    m_impl->device = rtcNewDevice(config.empty() ? nullptr : config.c_str());
    if (!m_impl->device) throw Error("embree: rtcNewDevice failed");
    m_impl->positions.assign(positions.begin(), positions.end());
    m_impl->indices.assign(indices.begin(), indices.end());
    m_impl->build();
}

EmbreePeer::~EmbreePeer() {
    if (!m_impl) return;
    if (m_impl->scene) rtcReleaseScene(m_impl->scene);
    if (m_impl->device) rtcReleaseDevice(m_impl->device);
}

double EmbreePeer::build_ms() const {
    return m_impl->build_ms;
}

double EmbreePeer::rebuild() {
    m_impl->build();
    return m_impl->build_ms;
}

bool EmbreePeer::intersect(float3 origin, float3 direction, float tmin, float tmax, float& t,
                           uint32_t& prim) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = origin.x, rh.ray.org_y = origin.y, rh.ray.org_z = origin.z;
    rh.ray.dir_x = direction.x, rh.ray.dir_y = direction.y, rh.ray.dir_z = direction.z;
    rh.ray.tnear = tmin;
    rh.ray.tfar = tmax;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xffffffffu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(m_impl->scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    t = rh.ray.tfar;
    prim = rh.hit.primID;
    return true;
}

bool EmbreePeer::occluded(float3 origin, float3 direction, float tmin, float tmax) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray;
    ray.org_x = origin.x, ray.org_y = origin.y, ray.org_z = origin.z;
    ray.dir_x = direction.x, ray.dir_y = direction.y, ray.dir_z = direction.z;
    ray.tnear = tmin;
    ray.tfar = tmax;
    ray.time = 0.0f;
    ray.mask = 0xffffffffu;
    ray.id = 0;
    ray.flags = 0;
    rtcOccluded1(m_impl->scene, &context, &ray);
    return ray.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
}

#else

struct EmbreePeer::Impl {};

bool EmbreePeer::available() {
    return false;
}

EmbreePeer::EmbreePeer(std::span<const float3>, std::span<const uint3>, unsigned) {
    throw Error("embree: this build has no Embree (install libembree-dev and re-run CMake)");
}
EmbreePeer::~EmbreePeer() = default;
double EmbreePeer::build_ms() const {
    return 0.0;
}
double EmbreePeer::rebuild() {
    return 0.0;
}
bool EmbreePeer::intersect(float3, float3, float, float, float&, uint32_t&) const {
    return false;
}
bool EmbreePeer::occluded(float3, float3, float, float) const {
    return false;
}

#endif

}  // namespace lucent::bench

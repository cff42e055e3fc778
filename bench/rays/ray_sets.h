// The ray sets of shared/BENCH.md: primary rays from the camera, and from the primary hits
// of an engine the shadow rays (to the point light) and the diffuse rays (cosine-weighted).
// Every engine `lucent bench rays` times (the kernels, Embree, the programs of
// rays_programs.h) traces these.
#pragma once

#include <cstdint>
#include <vector>

#include "bench/common/bench_camera.h"
#include "lucent/device/types.h"
#include "lucent/device/vector_math.h"
#include "scene/obj_mesh.h"

namespace lucent::bench {

/// A set of rays in SoA, and per ray the pixel it came from.
struct RaySet {
    std::vector<float3> origin, direction;
    std::vector<float> tmax;
    std::vector<uint32_t> pixel;
    size_t size() const { return origin.size(); }
    void add(float3 o, float3 d, float t, uint32_t p) {
        origin.push_back(o);
        direction.push_back(d);
        tmax.push_back(t);
        pixel.push_back(p);
    }
};

/// One ray per pixel of a w x h image, through the pixel's centre, tmax infinite.
RaySet primary_rays(const Camera& cam, unsigned w, unsigned h);

/// Shadow and diffuse rays from the primary hits of one engine (BENCH.md): t[i] negative
/// where primary ray i missed, prim[i] the triangle it hit.
void secondary_rays(const RaySet& primary, const float* t, const uint32_t* prim,
                    const scene::ObjMesh& mesh, float3 light, RaySet& shadow, RaySet& diffuse);

}  // namespace lucent::bench

#include "bench/rays/ray_sets.h"

#include <algorithm>
#include <cmath>

namespace lucent::bench {

namespace {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kOffset = 1e-3f;  // secondary ray origins: p + 1e-3 n (BENCH.md)

uint32_t hash(uint32_t a) {
    a ^= a >> 16;
    a *= 0x7feb352du;
    a ^= a >> 15;
    a *= 0x846ca68bu;
    a ^= a >> 16;
    return a;
}

}  // namespace

RaySet primary_rays(const Camera& cam, unsigned w, unsigned h) {
    const float3 fwd = normalize(cam.look - cam.eye);
    const float3 right = normalize(cross(fwd, cam.up));
    const float3 up2 = cross(right, fwd);
    const float t = std::tan(cam.fov / 2 * kPi / 180);
    const float a = (float)w / (float)h;
    RaySet rays;
    for (unsigned y = 0; y < h; ++y)
        for (unsigned x = 0; x < w; ++x) {
            float u = (2 * (x + 0.5f) / w - 1) * t * a;
            float v = (1 - 2 * (y + 0.5f) / h) * t;
            rays.add(cam.eye, normalize(fwd + u * right + v * up2), kInfinity, y * w + x);
        }
    return rays;
}

void secondary_rays(const RaySet& primary, const float* t, const uint32_t* prim,
                    const scene::ObjMesh& mesh, float3 light, RaySet& shadow, RaySet& diffuse) {
    for (size_t i = 0; i < primary.size(); ++i) {
        if (t[i] < 0.0f) continue;
        const float3 d = primary.direction[i];
        const float3 p = primary.origin[i] + t[i] * d;
        const uint3 tri = mesh.indices[prim[i]];
        const float3 v0 = mesh.positions[tri.x];
        float3 n = normalize(cross(mesh.positions[tri.y] - v0, mesh.positions[tri.z] - v0));
        if (dot(n, d) > 0.0f) n = -n;
        const float3 o = p + kOffset * n;
        const float3 to_light = light - o;
        const float dist = length(to_light);
        shadow.add(o, to_light / dist, dist, primary.pixel[i]);

        const uint32_t h1 = hash(2 * primary.pixel[i] + 1), h2 = hash(h1);
        const float u1 = (float)(h1 >> 8) / 16777216.0f, u2 = (float)(h2 >> 8) / 16777216.0f;
        const float r = std::sqrt(u1), phi = 2 * kPi * u2;
        const float3 tt = normalize(
            cross(n, std::fabs(n.x) > 0.5f ? make_float3(0, 1, 0) : make_float3(1, 0, 0)));
        const float3 bb = cross(n, tt);
        const float3 dir = normalize(tt * (r * std::cos(phi)) + bb * (r * std::sin(phi)) +
                                     n * std::sqrt(std::max(0.0f, 1 - u1)));
        diffuse.add(o, dir, kInfinity, primary.pixel[i]);
    }
}

}  // namespace lucent::bench

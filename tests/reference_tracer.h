// A brute-force reference for the global illumination tests: every triangle of a scene::Scene
// tested against every ray (Moller-Trumbore, double precision), no acceleration, no engine.
// Independent of Lucent's traversal on purpose, so that it can judge it.
#pragma once

#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "scene/scene.h"

namespace lucent_tests {

struct ReferenceHit {
    double t;
    float3 position, normal;  // normal faces the ray's origin
    float3 albedo;
};

class ReferenceTracer {
  public:
    explicit ReferenceTracer(const lucent::scene::Scene& scene) : m_scene(scene) {}

    /// The nearest hit of origin + t dir for t in (tmin, tmax).
    std::optional<ReferenceHit> trace(float3 origin, float3 dir, double tmin = 1e-6,
                                      double tmax = 1e30) const {
        std::optional<ReferenceHit> best;
        for (const auto& mesh : m_scene.meshes)
            for (size_t i = 0; i < mesh.indices.size(); ++i) {
                const uint3 t = mesh.indices[i];
                const float3 a = mesh.positions[t.x], b = mesh.positions[t.y],
                             c = mesh.positions[t.z];
                const double hit_t = intersect(origin, dir, a, b, c);
                if (hit_t > tmin && hit_t < tmax && (!best || hit_t < best->t)) {
                    float3 n = normalize(cross(b - a, c - a));
                    if (dot(n, dir) > 0) n = -n;
                    best = ReferenceHit{hit_t, origin + float(hit_t) * dir, n,
                                        m_scene.materials[mesh.materials[i]].diffuse};
                }
            }
        return best;
    }

    bool visible(float3 from, float3 to) const {
        return !trace(from, to - from, 1e-6, 0.999).has_value();
    }

    /// Radiance leaving hit h towards the camera side by direct light from the point lights
    /// (Lambertian: rho / pi times the irradiance).
    float3 reflected_direct(const ReferenceHit& h, float epsilon) const {
        float3 sum = make_float3(0.0f);
        const float3 origin = h.position + epsilon * h.normal;
        for (const auto& light : m_scene.point_lights) {
            const float3 to = light.position - h.position;
            const float d2 = dot(to, to), c = dot(h.normal, to) / std::sqrt(d2);
            if (c > 0 && visible(origin, light.position)) sum += light.intensity * (c / d2);
        }
        return h.albedo * sum * float(1.0 / M_PI);
    }

    /// Irradiance at x (normal n) from light that reached the scene directly from the point
    /// lights and then reflected once: cosine-weighted Monte Carlo, E = pi / N sum L.
    float3 one_bounce_irradiance(float3 x, float3 n, int samples, float epsilon,
                                 std::mt19937& rng) const {
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        const float3 t = normalize(
            cross(n, std::fabs(n.x) > 0.5f ? make_float3(0, 1, 0) : make_float3(1, 0, 0)));
        const float3 b = cross(n, t);
        float3 sum = make_float3(0.0f);
        for (int s = 0; s < samples; ++s) {
            const float u1 = u(rng), u2 = u(rng);
            const float r = std::sqrt(u1), phi = float(2 * M_PI) * u2;
            const float3 d = t * (r * std::cos(phi)) + b * (r * std::sin(phi)) +
                             n * std::sqrt(std::max(0.0f, 1.0f - u1));
            if (auto h = trace(x, d)) sum += reflected_direct(*h, epsilon);
        }
        return sum * float(M_PI / samples);
    }

  private:
    static double intersect(float3 o, float3 d, float3 a, float3 b, float3 c) {
        const double e1[3] = {double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z};
        const double e2[3] = {double(c.x) - a.x, double(c.y) - a.y, double(c.z) - a.z};
        const double dd[3] = {d.x, d.y, d.z};
        const double p[3] = {dd[1] * e2[2] - dd[2] * e2[1], dd[2] * e2[0] - dd[0] * e2[2],
                             dd[0] * e2[1] - dd[1] * e2[0]};
        const double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
        if (std::fabs(det) < 1e-18) return -1;
        const double s[3] = {double(o.x) - a.x, double(o.y) - a.y, double(o.z) - a.z};
        const double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
        if (u < 0 || u > 1) return -1;
        const double q[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2],
                             s[0] * e1[1] - s[1] * e1[0]};
        const double v = (dd[0] * q[0] + dd[1] * q[1] + dd[2] * q[2]) / det;
        if (v < 0 || u + v > 1) return -1;
        return (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
    }

    const lucent::scene::Scene& m_scene;
};

}  // namespace lucent_tests

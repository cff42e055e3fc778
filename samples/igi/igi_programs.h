// Instant Global Illumination (Marques and Santos, seed §4), canonical form: virtual point
// lights (VPLs) from particles traced out of the point lights along Halton paths; per pixel,
// direct light and a Whitted tree of specular reflections; indirect diffuse light from the
// VPLs by Eq. (1) with the bounded geometry term at every diffuse hit of the tree. (The
// paper's accelerations separate the indirect term at the primary hit: not done yet.)
#pragma once

#include "lucent/device.h"

namespace igi {

enum : unsigned { kRadianceRay = 0, kShadowRay = 1, kParticleRay = 2, kVplShadowRay = 3 };

struct PointLight {
    float3 position;
    float3 intensity;
};

/// A VPL: where a light path met a diffuse surface, and Le,k of Eq. (1): the flux that
/// arrived there times rho / pi (it reflects diffusely).
struct Vpl {
    float3 position;
    float3 normal;
    float3 radiance;
};

struct HitAttributes {
    float3 geometric_normal;  // object space, not normalised
};

struct RadiancePayload {
    float3 color;
    int depth;
};
struct ShadowPayload {
    float visible;
};
struct ParticlePayload {
    bool hit;
    float3 position, normal, albedo;
};

/// Radical inverse in base b (Halton 1960): the i-th point of a low-discrepancy sequence.
LUCENT_HD inline float halton(unsigned i, unsigned base) {
    float f = 1.0f, r = 0.0f;
    while (i > 0) {
        f /= float(base);
        r += f * float(i % base);
        i /= base;
    }
    return r;
}

/// Eq. (1)'s smoothing f(a, b, d): 0 below a, 1 above b, quadratic in between.
LUCENT_HD inline float smoothing(float a, float b, float d) {
    if (d < a) return 0.0f;
    if (d > b) return 1.0f;
    const float t = (d - a) / (b - a);
    return t * t;
}

LUCENT_HD inline float3 cosine_direction(float3 n, float u1, float u2) {
    const float r = sqrtf(u1), phi = 6.2831853f * u2;
    const float3 t =
        normalize(cross(n, fabsf(n.x) > 0.5f ? make_float3(0, 1, 0) : make_float3(1, 0, 0)));
    const float3 b = cross(n, t);
    return normalize(t * (r * cosf(phi)) + b * (r * sinf(phi)) +
                     n * sqrtf(lc_max(0.0f, 1.0f - u1)));
}

struct GenerateRecord {
    lucent::BufferView<PointLight> lights;
    lucent::BufferView<Vpl> vpls;  // paths x bounces slots; unused ones have zero radiance
    unsigned bounces;
    float scene_epsilon;
    lucent::Handle top_object;
};
LUCENT_RECORD(GenerateRecord, lights, vpls, bounces, scene_epsilon, top_object)

struct CameraRecord {
    float3 eye, U, V, W;
    lucent::BufferView<float4> output;
    lucent::Handle top_object;
};
LUCENT_RECORD(CameraRecord, eye, U, V, W, output, top_object)

struct SurfaceRecord {
    float3 Kd, Ks, Ke;
    lucent::BufferView<PointLight> lights;
    lucent::BufferView<Vpl> vpls;
    float min_d;  // Eq. (1)'s bounding distance
    unsigned max_depth;
    float scene_epsilon;
    lucent::Handle top_object;
    unsigned imperfect_visibility;  // VPL shadow rays against the boxes graph (seed §4.1)
    lucent::Handle vpl_shadow_object;
};
LUCENT_RECORD(SurfaceRecord, Kd, Ks, Ke, lights, vpls, min_d, max_depth, scene_epsilon, top_object,
              imperfect_visibility, vpl_shadow_object)

struct ParticleRecord {
    float3 Kd;
};
LUCENT_RECORD(ParticleRecord, Kd)

struct MeshRecord {
    lucent::BufferView<float3> positions;
    lucent::BufferView<uint3> triangles;
};
LUCENT_RECORD(MeshRecord, positions, triangles)

LUCENT_HD inline bool visible(const SurfaceRecord& rec, float3 from, float3 to) {
    ShadowPayload s{1.0f};
    lucent::trace(rec.top_object,
                  lucent::make_ray(from, to - from, kShadowRay, rec.scene_epsilon, 0.999f), s);
    return s.visible > 0.0f;
}

/// V(x, yk) of Eq. (1): against the scene, or, with imperfect visibility (seed §4.1), against
/// the crude second graph of the triangles' bounding boxes (a different root and ray type).
LUCENT_HD inline bool vpl_visible(const SurfaceRecord& rec, float3 from, float3 to) {
    if (!rec.imperfect_visibility) return visible(rec, from, to);
    ShadowPayload s{1.0f};
    lucent::trace(rec.vpl_shadow_object,
                  lucent::make_ray(from, to - from, kVplShadowRay, rec.scene_epsilon, 0.999f), s);
    return s.visible > 0.0f;
}

/// Eq. (1) at x with normal n: sum over the VPLs of Le,k V(x, yk) G(x, yk), where G is
/// bounded by f(0.8 min_d, 1.2 min_d, |x - yk|). Irradiance-like: rho/pi multiplies it.
LUCENT_HD inline float3 indirect(const SurfaceRecord& rec, float3 x, float3 n) {
    float3 sum = make_float3(0.0f);
    for (unsigned k = 0; k < rec.vpls.count(); ++k) {
        const Vpl vpl = rec.vpls[k];
        if (max_component(vpl.radiance) <= 0.0f) continue;
        const float3 to = vpl.position - x;
        const float d2 = dot(to, to), d = sqrtf(d2);
        const float cos_x = dot(n, to) / d, cos_y = -dot(vpl.normal, to) / d;
        if (cos_x <= 0.0f || cos_y <= 0.0f) continue;
        const float g = cos_x * cos_y / d2 * smoothing(0.8f * rec.min_d, 1.2f * rec.min_d, d);
        if (g > 0.0f && vpl_visible(rec, x, vpl.position)) sum += vpl.radiance * g;
    }
    return sum;
}

}  // namespace igi

// ---- VPL generation: one thread per light path --------------------------------------------
LUCENT_RAY_GENERATION(igi_generate_vpls, igi::GenerateRecord) {
    const unsigned path = lucent::launch_index().x, paths = lucent::launch_size().x;
    for (unsigned b = 0; b < rec.bounces; ++b) rec.vpls[path * rec.bounces + b] = igi::Vpl{};
    const igi::PointLight light = rec.lights[path % rec.lights.count()];
    // Uniform direction on the sphere from Halton dimensions 2 and 3.
    const unsigned i = path + 1;
    const float z = 1.0f - 2.0f * igi::halton(i, 2), phi = 6.2831853f * igi::halton(i, 3);
    const float s = sqrtf(lc_max(0.0f, 1.0f - z * z));
    float3 direction = make_float3(s * cosf(phi), s * sinf(phi), z);
    float3 origin = light.position;
    // Each path carries an equal share of the lights' total flux 4 pi I.
    float3 flux = light.intensity * (4.0f * 3.14159265f * float(rec.lights.count()) / float(paths));
    const unsigned primes[] = {5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43};
    for (unsigned b = 0; b < rec.bounces; ++b) {
        igi::ParticlePayload hit{};
        lucent::trace(rec.top_object,
                      lucent::make_ray(origin, direction, igi::kParticleRay, rec.scene_epsilon),
                      hit);
        if (!hit.hit || max_component(hit.albedo) <= 0.0f) break;  // a VPL only where diffuse
        const float3 n = faceforward(hit.normal, direction);
        rec.vpls[path * rec.bounces + b] =
            igi::Vpl{hit.position, n, flux * hit.albedo * (1.0f / 3.14159265f)};
        flux = flux * hit.albedo;  // cosine sampling cancels the cosine and pi
        origin = hit.position + rec.scene_epsilon * n;
        direction = igi::cosine_direction(n, igi::halton(i, primes[(2 * b) % 12]),
                                          igi::halton(i, primes[(2 * b + 1) % 12]));
    }
}

LUCENT_CLOSEST_HIT(igi_particle_hit, igi::ParticleRecord, igi::ParticlePayload,
                   igi::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    prd.hit = true;
    prd.position = ray.origin + lucent::t_hit() * ray.direction;
    prd.normal = normalize(lucent::object_to_world_normal(attr.geometric_normal));
    prd.albedo = rec.Kd;
}

// ---- per pixel: direct light, the specular tree, and Eq. (1) -------------------------------
LUCENT_RAY_GENERATION(igi_camera, igi::CameraRecord) {
    const uint3 p = lucent::launch_index(), n = lucent::launch_size();
    const float sx = 2.0f * (p.x + 0.5f) / n.x - 1.0f, sy = 1.0f - 2.0f * (p.y + 0.5f) / n.y;
    igi::RadiancePayload prd{make_float3(0.0f), 0};
    lucent::trace(rec.top_object,
                  lucent::make_ray(rec.eye, normalize(rec.W + sx * rec.U + sy * rec.V),
                                   igi::kRadianceRay, 0.0f),
                  prd);
    rec.output[make_uint2(p.x, p.y)] = make_float4(prd.color, 1.0f);
}

LUCENT_CLOSEST_HIT(igi_surface, igi::SurfaceRecord, igi::RadiancePayload, igi::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    const float3 x = ray.origin + lucent::t_hit() * ray.direction;
    const float3 n = faceforward(normalize(lucent::object_to_world_normal(attr.geometric_normal)),
                                 ray.direction);
    const float3 origin = x + rec.scene_epsilon * n;
    float3 color = rec.Ke;
    const float3 albedo = rec.Kd * (1.0f / 3.14159265f);
    if (max_component(rec.Kd) > 0.0f) {
        for (unsigned l = 0; l < rec.lights.count(); ++l) {
            const igi::PointLight light = rec.lights[l];
            const float3 to = light.position - x;
            const float d2 = dot(to, to), c = dot(n, to) / sqrtf(d2);
            if (c > 0.0f && igi::visible(rec, origin, light.position))
                color += albedo * light.intensity * (c / d2);
        }
        color += albedo * igi::indirect(rec, origin, n);
    }
    if (max_component(rec.Ks) > 0.0f && prd.depth + 1 < int(rec.max_depth)) {
        igi::RadiancePayload reflected{make_float3(0.0f), prd.depth + 1};
        lucent::trace(
            rec.top_object,
            lucent::make_ray(origin, reflect(normalize(ray.direction), n), igi::kRadianceRay, 0.0f),
            reflected);
        color += rec.Ks * reflected.color;
    }
    prd.color = color;
}

LUCENT_MISS(igi_miss, lucent::NoRecord, igi::RadiancePayload) {
    prd.color = make_float3(0.0f);
}

LUCENT_ANY_HIT(igi_shadow_blocked, lucent::NoRecord, igi::ShadowPayload, igi::HitAttributes) {
    prd.visible = 0.0f;
    lucent::terminate_ray();
}

LUCENT_ATTRIBUTE(igi_attributes, igi::MeshRecord, igi::HitAttributes) {
    const uint3 t = rec.triangles[prim];
    attr.geometric_normal =
        cross(rec.positions[t.y] - rec.positions[t.x], rec.positions[t.z] - rec.positions[t.x]);
}

// ---- the crude scene of imperfect visibility: one box per triangle -------------------------
LUCENT_BOUNDING_BOX(igi_triangle_box_bounds, igi::MeshRecord) {
    const uint3 t = rec.triangles[prim];
    const float3 a = rec.positions[t.x], b = rec.positions[t.y], c = rec.positions[t.z];
    box.lo = fminf(a, fminf(b, c));
    box.hi = fmaxf(a, fmaxf(b, c));
}

LUCENT_INTERSECTION(igi_triangle_box_intersect, igi::MeshRecord, igi::HitAttributes) {
    const uint3 t = rec.triangles[prim];
    const float3 a = rec.positions[t.x], b = rec.positions[t.y], c = rec.positions[t.z];
    const float3 lo = fminf(a, fminf(b, c)), hi = fmaxf(a, fmaxf(b, c));
    const lucent::Ray& ray = lucent::current_ray();
    // Slab test; a flat box (an axis-aligned triangle) still stops rays that cross its plane.
    float t0 = ray.tmin, t1 = ray.tmax;
    const float o[3] = {ray.origin.x, ray.origin.y, ray.origin.z};
    const float d[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
    const float l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0.0f) {
            if (o[k] < l[k] || o[k] > h[k]) return;
            continue;
        }
        float near = (l[k] - o[k]) / d[k], far = (h[k] - o[k]) / d[k];
        if (near > far) {
            const float tmp = near;
            near = far;
            far = tmp;
        }
        t0 = lc_max(t0, near);
        t1 = lc_min(t1, far * 1.00000024f);
        if (t0 > t1) return;
    }
    if (lucent::potential_intersection(t0)) {
        attr.geometric_normal = cross(b - a, c - a);
        lucent::report_intersection(0);
    }
}

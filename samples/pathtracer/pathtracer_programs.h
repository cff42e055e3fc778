// A progressive Monte Carlo path tracer in the structure of the OptiX paper's Design Garage
// (OptiX paper §6.2, Figure 8): the ray-generation program iterates over the bounces of a path
// instead of recursing; each material's closest-hit program returns the next ray, the
// throughput of the bounce and the light it found (emission, and next-event estimation with
// multiple importance sampling, Veach 1997 §9.2, power heuristic) through the payload. Every
// launch adds one sample per pixel to a float4 accumulation buffer whose w counts them.
#pragma once

#include "lucent/device.h"
#include "samples/common/common_programs.h"
#include "samples/pathtracer/pathtracer_bsdf.h"

namespace pathtracer {

/// The module of this sample's programs (lucent/device/module.h).
LUCENT_MODULE(pathtracer, lucent::kUsesOccluded)

enum : unsigned { kRadianceRay = 0, kShadowRay = 1 };

using sample_common::AreaLight;
using sample_common::PointLight;

/// What a bounce hands back to the ray-generation loop.
struct PathPayload {
    unsigned rng;     // in: the path's random state; out: advanced
    unsigned nee;     // in: 1 to sample the lights at this vertex
    unsigned done;    // out: 1 when the path ends here (miss, or absorbed)
    unsigned delta;   // out: the next direction came from a delta lobe
    float3 emitted;   // out: emitted radiance towards the ray (Le)
    float light_pdf;  // out: solid-angle pdf of light sampling choosing that point
    float3 direct;    // out: light arriving by next-event estimation, reflected (MIS-weighted)
    float3 weight;    // out: f cos / pdf of the next direction
    float pdf;        // out: solid-angle pdf of the next direction
    float3 origin, direction;  // out: the next ray
};
struct ShadowPayload {  // the shadow ray type's declared payload; lucent::occluded() uses none
    float visible;
};

/// What a triangle hit gives the hit programs (sample_common::mesh_normal_uv): the normal
/// and the texture coordinate of the diffuse map.
using HitAttributes = sample_common::MeshNormalUv;

/// PCG-RXS-M-XS 32 (O'Neill 2014) as a stream: advances the state, returns [0, 1).
LUCENT_HD inline float next_random(unsigned& state) {
    state = state * 747796405u + 2891336453u;
    unsigned word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    word = (word >> 22u) ^ word;
    return float(word >> 8) * (1.0f / 16777216.0f);
}

/// The first state of the path of pixel `pixel` in frame `frame`: TEA as a hash (Zafar et
/// al. 2010), the same on both backends; `seed` selects an independent set of streams.
LUCENT_HD inline unsigned path_seed(unsigned pixel, unsigned frame, unsigned seed) {
    const uint4 k = lucent::zafar_tea_key();
    return lucent::tea<16>(make_uint2(pixel, frame), make_uint4(k.x, k.y ^ seed, k.z, k.w)).x;
}

/// Veach's power heuristic with beta = 2 for one sample of each strategy.
LUCENT_HD inline float power_heuristic(float pdf_a, float pdf_b) {
    const float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
    return a + b > 0.0f ? a / (a + b) : 0.0f;
}

/// Solid-angle pdf with which next_event would choose the point at distance t along the unit
/// direction from origin: light l with probability p(l) (its power's share), then a uniform
/// point on its area A_l, p(l) / A_l per unit area; per solid angle that is
/// p(l) / A_l x t^2 / cos(theta_light) (Veach 1997, §8.2.2.2).
LUCENT_HD inline float area_light_pdf(lucent::BufferView<AreaLight> lights,
                                      lucent::BufferView<const float> cdf, float3 origin,
                                      float3 direction, float t) {
    float pdf = 0.0f;
    for (unsigned l = 0; l < lights.count(); ++l) {
        const AreaLight light = lights[l];
        const float tl = sample_common::light_hit_distance(light, origin, direction);
        // Not on this light: relative, as the rounding of both distances is at any scale.
        if (tl <= 0.0f || fabsf(tl - t) > 1e-3f * t) continue;
        const float cos_light = -dot(sample_common::light_normal(light), direction);
        pdf += sample_common::light_probability(cdf, l) * tl * tl /
               (cos_light * sample_common::light_area(light));
    }
    return pdf;
}

struct CameraRecord {
    lucent::BufferView<sample_common::PinholeCamera> camera;  // one element
    lucent::BufferView<float4> accum;   // running sums; w counts the samples (the frame)
    lucent::BufferView<float4> output;  // the average, exposed and tone mapped
    /// One element added to the frame's random streams: the viewer's temporal denoiser
    /// restarts the accumulation every frame and must not restart the streams with it.
    lucent::BufferView<const unsigned> stream_offset;
    lucent::Handle top_object;
    unsigned max_depth;  // path segments from the eye
    unsigned rr_depth;   // bounces before Russian roulette starts
    unsigned nee;        // 0: BSDF sampling only
    unsigned seed;
    float exposure;
    unsigned reinhard;  // 1: L / (1 + L) per channel after the exposure
};
LUCENT_RECORD(CameraRecord, camera, accum, output, stream_offset, top_object, max_depth, rr_depth,
              nee, seed, exposure, reinhard)

struct SurfaceRecord {
    float3 Kd, Ks, Ke;
    lucent::TextureView diffuse_map;  // multiplies Kd; a 1x1 white texel when there is none
    // Multiplies Ks: a glTF metal's base colour texture (its colour is its F0), else white.
    lucent::TextureView specular_map;
    float alpha, ior;
    lucent::BufferView<AreaLight> area_lights;
    lucent::BufferView<const float> area_light_cdf;  // next-event estimation picks by power
    lucent::BufferView<PointLight> point_lights;
    float scene_size;  // of its bounds: sample_common::offset_ray_origin
    lucent::Handle top_object;
};
LUCENT_RECORD(SurfaceRecord, Kd, Ks, Ke, diffuse_map, specular_map, alpha, ior, area_lights,
              area_light_cdf, point_lights, scene_size, top_object)

struct MissRecord {
    float3 environment;  // uniform radiance from every direction
};
LUCENT_RECORD(MissRecord, environment)

/// Nothing between `from` and `to`, both moved off their surfaces
/// (sample_common::offset_ray_origin) or `to` a point light: an occlusion query (every
/// surface opaque, no programs run).
LUCENT_HD inline bool unoccluded(const SurfaceRecord& rec, float3 from, float3 to) {
    lucent::Ray ray = sample_common::segment_ray(from, to, kShadowRay);
    ray.time = lucent::ray_time();  // the path's instant (motion blur)
    return !lucent::occluded(rec.top_object, ray);
}

/// next_event's shadow test: is nothing between `from` and `to`? `light` is the index of the
/// light sampled, area lights first, then point lights. This one, the path tracer's, is
/// unoccluded() for every light; a sample that links lights to objects passes its own
/// (samples/hair/hair_programs.h masks each light's shadow rays).
struct SceneShadows {
    LUCENT_HD bool operator()(const SurfaceRecord& rec, float3 from, float3 to, unsigned) const {
        return unoccluded(rec, from, to);
    }
};

/// Next-event estimation at p: one area light chosen in proportion to its power, a uniform
/// point on its area, weighted by the power heuristic against BSDF sampling; every point
/// light (delta: no MIS). `shadows` decides what blocks each light (SceneShadows: anything).
template <class Shadows = SceneShadows>
LUCENT_HD inline float3 next_event(const SurfaceRecord& rec, const Bsdf& bsdf, const Frame& frame,
                                   float3 wo, float3 p, unsigned& rng,
                                   const Shadows& shadows = Shadows()) {
    float3 sum = make_float3(0.0f);
    const unsigned n = rec.area_lights.count();
    if (n > 0) {
        const unsigned l = sample_common::pick_light(rec.area_light_cdf, next_random(rng));
        const float u = next_random(rng), v = next_random(rng);
        const AreaLight light = rec.area_lights[l];
        const float3 q = sample_common::light_point(light, u, v);
        const float area = sample_common::light_area(light);
        const float3 to = q - p;
        const float d2 = dot(to, to), d = sqrtf(d2);
        const float3 wi = to / d;
        const float3 light_normal = sample_common::light_normal(light);
        const float cos_light = -dot(light_normal, wi);  // > 0: emitting side
        const float3 wi_local = to_local(frame, wi);
        const float chosen = sample_common::light_probability(rec.area_light_cdf, l);
        if (cos_light > 0.0f && wi_local.z > 0.0f && chosen > 0.0f) {
            // The area pdf p(l) / A as a solid-angle pdf: times d^2 / cos(theta_light).
            const float pdf_light = chosen * d2 / (cos_light * area);
            const float3 f = bsdf_eval(bsdf, wo, wi_local);
            if (max_component(f) > 0.0f &&
                shadows(rec, p,
                        sample_common::offset_ray_origin(q, light_normal, rec.scene_size), l)) {
                const float w = power_heuristic(pdf_light, bsdf_pdf(bsdf, wo, wi_local));
                sum += f * light.emission * (wi_local.z * w / pdf_light);
            }
        }
    }
    for (unsigned l = 0; l < rec.point_lights.count(); ++l) {
        const PointLight light = rec.point_lights[l];
        const float3 to = light.position - p;
        const float d2 = dot(to, to), d = sqrtf(d2);
        const float3 wi = to / d, wi_local = to_local(frame, wi);
        if (wi_local.z <= 0.0f) continue;
        const float3 f = bsdf_eval(bsdf, wo, wi_local);
        if (max_component(f) > 0.0f && shadows(rec, p, light.position, n + l))
            sum += f * light.intensity * (wi_local.z / d2);
    }
    return sum;
}

/// The closest hit every material shares (CACM §6.2: a generic light loop; the BSDF of
/// `Kind` samples and evaluates): emission, next-event estimation, the next ray. `attr`'s
/// normal may be of any primitive (a sample shading built-in spheres or curves passes
/// theirs, uv 0); `shadows` is next_event's.
template <unsigned Kind, class Shadows = SceneShadows>
LUCENT_HD inline void shade(const SurfaceRecord& rec, PathPayload& prd, const HitAttributes& attr,
                            const Shadows& shadows = Shadows()) {
    const lucent::Ray& ray = lucent::current_ray();
    const float t = lucent::t_hit();
    const float3 x = ray.origin + t * ray.direction;
    const float3 ng = normalize(lucent::object_to_world_normal(attr.geometric_normal));
    const bool outside = dot(ng, ray.direction) < 0.0f;
    const float3 n = outside ? ng : -ng;
    // Surfaces emit on the side their winding makes the front, as area lights do.
    prd.emitted = outside ? rec.Ke : make_float3(0.0f);
    prd.light_pdf = outside && max_component(rec.Ke) > 0.0f
                        ? area_light_pdf(rec.area_lights, rec.area_light_cdf, ray.origin,
                                         ray.direction, t)
                        : 0.0f;

    const float3 diffuse = rec.Kd * sample_common::diffuse_texel(rec.diffuse_map, attr.uv);
    const float3 specular = rec.Ks * sample_common::diffuse_texel(rec.specular_map, attr.uv);
    const Bsdf bsdf{Kind, diffuse, specular, rec.alpha,
                    Kind == kDielectric && !outside ? 1.0f / rec.ior : rec.ior};
    const Frame frame = make_frame(n);
    const float3 wo = to_local(frame, -ray.direction);
    const float3 above = sample_common::offset_ray_origin(x, n, rec.scene_size);
    prd.direct = make_float3(0.0f);
    if (prd.nee && !is_delta(bsdf))
        prd.direct = next_event(rec, bsdf, frame, wo, above, prd.rng, shadows);

    const float u1 = next_random(prd.rng), u2 = next_random(prd.rng), u3 = next_random(prd.rng);
    const BsdfSample s = bsdf_sample(bsdf, wo, u1, u2, u3);
    if (s.pdf <= 0.0f || max_component(s.weight) <= 0.0f) {
        prd.done = 1;
        return;
    }
    prd.weight = s.weight;
    prd.pdf = s.pdf;
    prd.delta = s.delta ? 1u : 0u;
    prd.direction = normalize(to_world(frame, s.wi));
    prd.origin = s.wi.z > 0.0f ? above : sample_common::offset_ray_origin(x, -n, rec.scene_size);
}

// ---- the path loop (CACM Figure 8) -----------------------------------------------------------
/// One more sample of the pixel at the launch index into rec.accum, and the mean into
/// rec.output.
LUCENT_HD inline void trace_pixel(const CameraRecord& rec) {
    const uint3 i = lucent::launch_index(), n = lucent::launch_size();
    const uint2 pixel = make_uint2(i.x, i.y);
    float4 accum = rec.accum[pixel];
    unsigned rng = path_seed(i.y * n.x + i.x, unsigned(accum.w) + rec.stream_offset[0u], rec.seed);
    // A uniformly jittered position in the pixel: the box filter's antialiasing.
    const float sx = 2.0f * (float(i.x) + next_random(rng)) / float(n.x) - 1.0f;
    const float sy = 1.0f - 2.0f * (float(i.y) + next_random(rng)) / float(n.y);
    // The path's time, uniform over the shutter [0, 1]: every ray of the path sees the scene
    // at that instant, so moving geometry blurs (a static scene ignores it).
    const float time = next_random(rng);
    const sample_common::PinholeCamera camera = rec.camera[0u];
    float3 origin = camera.eye, direction = sample_common::camera_direction(camera, sx, sy);
    float3 radiance = make_float3(0.0f), throughput = make_float3(1.0f);
    float previous_pdf = 0.0f;
    bool previous_delta = true;  // the camera's ray is found by no other strategy
    for (unsigned depth = 0; depth < rec.max_depth; ++depth) {
        PathPayload prd;
        prd.rng = rng;
        prd.nee = rec.nee && depth + 1 < rec.max_depth ? 1u : 0u;
        prd.done = 0;
        prd.delta = 0;
        lucent::trace(
            rec.top_object,
            lucent::make_ray(origin, direction, kRadianceRay, 0.0f, lucent::kInfinity, time), prd);
        rng = prd.rng;
        if (max_component(prd.emitted) > 0.0f) {
            // An emitter found by BSDF sampling: MIS against light sampling from the last
            // vertex, which was tried there unless that bounce was a delta lobe.
            const float w =
                rec.nee && !previous_delta ? power_heuristic(previous_pdf, prd.light_pdf) : 1.0f;
            radiance += throughput * prd.emitted * w;
        }
        if (prd.done) break;
        radiance += throughput * prd.direct;
        throughput *= prd.weight;
        if (depth + 1 >= rec.rr_depth) {
            // Russian roulette: continue with probability q, divide by it (unbiased).
            const float q = lc_min(max_component(throughput), 0.95f);
            if (next_random(rng) >= q) break;
            throughput = throughput / q;
        }
        previous_pdf = prd.pdf;
        previous_delta = prd.delta != 0;
        origin = prd.origin;
        direction = prd.direction;
    }
    // A NaN or infinity would poison the pixel for every later frame: drop that sample.
    const float sum = radiance.x + radiance.y + radiance.z;
    if (!(sum == sum) || sum > 3.0e38f) radiance = make_float3(0.0f);
    accum = make_float4(accum.x + radiance.x, accum.y + radiance.y, accum.z + radiance.z,
                        accum.w + 1.0f);
    rec.accum[pixel] = accum;
    float3 mean = make_float3(accum.x, accum.y, accum.z) * (rec.exposure / accum.w);
    if (rec.reinhard)
        mean = make_float3(mean.x / (1.0f + mean.x), mean.y / (1.0f + mean.y),
                           mean.z / (1.0f + mean.z));
    rec.output[pixel] = make_float4(mean, 1.0f);
}

LUCENT_RAY_GENERATION(pt_camera, pathtracer::CameraRecord) {
    pathtracer::trace_pixel(rec);
}

LUCENT_MISS(pt_miss, pathtracer::MissRecord, pathtracer::PathPayload) {
    prd.emitted = rec.environment;
    prd.light_pdf = 0.0f;  // the environment is never light-sampled
    prd.done = 1;
}

LUCENT_CLOSEST_HIT(pt_lambert, pathtracer::SurfaceRecord, pathtracer::PathPayload,
                   pathtracer::HitAttributes) {
    pathtracer::shade<pathtracer::kLambert>(rec, prd, attr);
}
LUCENT_CLOSEST_HIT(pt_metal, pathtracer::SurfaceRecord, pathtracer::PathPayload,
                   pathtracer::HitAttributes) {
    pathtracer::shade<pathtracer::kMetal>(rec, prd, attr);
}
LUCENT_CLOSEST_HIT(pt_dielectric, pathtracer::SurfaceRecord, pathtracer::PathPayload,
                   pathtracer::HitAttributes) {
    pathtracer::shade<pathtracer::kDielectric>(rec, prd, attr);
}
LUCENT_CLOSEST_HIT(pt_coated, pathtracer::SurfaceRecord, pathtracer::PathPayload,
                   pathtracer::HitAttributes) {
    pathtracer::shade<pathtracer::kCoated>(rec, prd, attr);
}

}  // namespace pathtracer

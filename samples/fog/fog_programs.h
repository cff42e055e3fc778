// Volumetric fog in the OptiX SDK's tutorial scene (Sebald, §3.1): a tiled floor and a
// reflective rusty box with procedural textures, a glass crystal (Fresnel, Beer absorption),
// an environment in the miss program, point lights with shadows; and a box of fog over the
// floor whose density is TEA gradient noise in x, z times a linear falloff in y.
//
// The fog box's any-hit lets shadow rays through. Its closest hit traces the same ray again
// against the solid objects alone, to find what lies beneath, then marches from where the ray
// enters the fog (or starts, inside it) to where it leaves or meets that surface, and composites
// the fog over it. Rays that start inside the fog (the camera, reflections off the floor)
// are shaded too: the paper's stated limitation is lifted by reporting a hit at the ray's
// start when its origin lies inside the box.
//
// Robust at any scale and position: secondary rays start at the hit point moved off the surface
// by Wächter and Binder's offset (Ray Tracing Gems, ch. 6; samples/common/ray_offset.h), which
// follows the float spacing at the hit and the scene's size, and are traced from tmin 0; the
// patterns and the noise read the point relative to the modelled scene's origin; every other
// length is the scene's (a march step, a noise lattice) or a share of the ray's own span.
#pragma once

#include "lucent/device.h"
#include "samples/common/common_programs.h"
#include "samples/common/ray_offset.h"
#include "lucent/device/noise.h"

namespace fog {

/// The module of this sample's programs (lucent/device/module.h).
LUCENT_MODULE(fog)

enum : unsigned { kRadianceRay = 0, kShadowRay = 1 };

using sample_common::PointLight;

struct HitAttributes {
    float3 normal;  // object space, not normalised (triangles); unit (fog box)
    float t_exit;   // fog box: where the ray leaves it
};

struct RadiancePayload {
    float3 color;
    float distance;  // to the surface shaded (1e30 for the environment)
    int depth;
};
struct ShadowPayload {
    float3 attenuation;
};

LUCENT_HD inline float3 xyz(float4 v) {
    return make_float3(v.x, v.y, v.z);
}

/// Unpolarised Fresnel reflectance of a dielectric for cos_i (> 0) and the index ratio
/// eta = n_incident / n_transmitted; 1 under total internal reflection.
LUCENT_HD inline float fresnel(float cos_i, float eta) {
    const float sin2_t = eta * eta * (1.0f - cos_i * cos_i);
    if (sin2_t >= 1.0f) return 1.0f;
    const float cos_t = sqrtf(1.0f - sin2_t);
    const float rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    const float rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5f * (rs * rs + rp * rp);
}

// ---- records ---------------------------------------------------------------------------
struct CameraRecord {
    lucent::BufferView<sample_common::PinholeCamera> camera;
    lucent::BufferView<float4> output;
    lucent::Handle top_object;
};
LUCENT_RECORD(CameraRecord, camera, output, top_object)

struct LightingParams {
    lucent::BufferView<PointLight> lights;
    float3 ambient;
    float scene_size;
    unsigned max_depth;
    lucent::Handle top_object;
};

/// A Phong surface with a procedural pattern: 0 floor tiles, 1 rust (gradient noise).
struct PhongRecord {
    float3 Kd_a, Kd_b;  // the pattern's two colours
    float3 Ks;
    float phong_exponent;
    float3 Kr;  // mirror reflection
    unsigned pattern;
    float pattern_scale;  // tile size, or noise lattice size
    uint4 noise_key;
    float3 model_origin;  // where the modelled scene's origin lies: patterns are relative to it
    lucent::BufferView<PointLight> lights;
    float3 ambient;
    float scene_size;  // the scene's longest side: ray offsets follow it
    unsigned max_depth;
    lucent::Handle top_object;
};
LUCENT_RECORD(PhongRecord, Kd_a, Kd_b, Ks, phong_exponent, Kr, pattern, pattern_scale, noise_key,
              model_origin, lights, ambient, scene_size, max_depth, top_object)

struct GlassRecord {
    float ior;
    float3 extinction;   // Beer's law: per unit distance inside the glass
    float3 shadow_tint;  // what a shadow ray keeps through the crystal
    float scene_size;
    unsigned max_depth;
    lucent::Handle top_object;
};
LUCENT_RECORD(GlassRecord, ior, extinction, shadow_tint, scene_size, max_depth, top_object)

struct FogBoxRecord {  // the fog box's bounds, for its bounding-box and intersection programs
    float3 box_min, box_max;
};
LUCENT_RECORD(FogBoxRecord, box_min, box_max)

struct FogRecord {
    float3 box_min, box_max;
    float density;      // extinction at full noise and the bottom of the box, per unit
    float step;         // march step along the ray
    float noise_scale;  // lattice size of the gradient noise, scene units
    unsigned noise;     // 0: uniform density (tests)
    unsigned falloff;   // 0: no falloff in y (tests)
    unsigned rounds;    // TEA rounds of the noise
    uint4 noise_key;    // generate_tea_key(device, seed): Sebald Fig. 4
    float3 model_origin;  // the noise is a function of the point relative to it
    float3 fog_color;
    lucent::Handle solid_object;  // the scene without the fog box
};
LUCENT_RECORD(FogRecord, box_min, box_max, density, step, noise_scale, noise, falloff, rounds,
              noise_key, model_origin, fog_color, solid_object)

struct MissRecord {
    lucent::TextureView environment;  // equirectangular; used when has_environment
    unsigned has_environment;
};
LUCENT_RECORD(MissRecord, environment, has_environment)

LUCENT_HD inline LightingParams lighting(const PhongRecord& r) {
    return LightingParams{r.lights, r.ambient, r.scene_size, r.max_depth, r.top_object};
}

/// What reaches p from `light`: its intensity over d^2 times what shadow rays let through.
/// The shadow ray leaves from `origin`, p moved off its surface, so it starts at tmin 0.
LUCENT_HD inline float3 light_arriving(const LightingParams& p, float3 origin, float3 to_light,
                                       const PointLight& light) {
    ShadowPayload s{make_float3(1.0f)};
    lucent::trace(p.top_object, lucent::make_ray(origin, to_light, kShadowRay, 0.0f, 0.999f), s);
    return light.intensity * s.attenuation * (1.0f / dot(to_light, to_light));
}

/// The procedural pattern's colour at p (relative to the modelled scene's origin).
LUCENT_HD inline float3 pattern_colour(const PhongRecord& r, float3 p) {
    p = p - r.model_origin;
    if (r.pattern == 0) {
        // Tiles with grout: checker of two shades, a darker line near each edge.
        const float u = p.x / r.pattern_scale, v = p.z / r.pattern_scale;
        const float fu = u - floorf(u), fv = v - floorf(v);
        const bool grout = fu < 0.03f || fv < 0.03f || fu > 0.97f || fv > 0.97f;
        const int checker = (int(floorf(u)) + int(floorf(v))) & 1;
        if (grout) return r.Kd_b * 0.35f;
        return checker ? r.Kd_a : lerp(r.Kd_a, r.Kd_b, 0.35f);
    }
    // Rust: patches of the second colour where gradient noise runs high.
    const float n =
        lucent::tea_gradient_noise((p.x + 0.7f * p.y) / r.pattern_scale,
                                   (p.z - 0.4f * p.y) / r.pattern_scale, r.noise_key, 2u);
    const float t = clampf((n - 0.45f) * 4.0f, 0.0f, 1.0f);
    return lerp(r.Kd_a, r.Kd_b, t);
}

/// Where the line o + t d enters and leaves the box (t0 > t1: it misses).
LUCENT_HD inline float2 box_span(float3 lo, float3 hi, float3 o, float3 d) {
    const float3 inv = make_float3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
    const float3 a = (lo - o) * inv, b = (hi - o) * inv;
    const float3 near = fminf(a, b), far = fmaxf(a, b);
    return make_float2(lc_max(near.x, lc_max(near.y, near.z)), lc_min(far.x, lc_min(far.y, far.z)));
}


// ---- camera, miss ------------------------------------------------------------------------
LUCENT_RAY_GENERATION(fog_camera, fog::CameraRecord) {
    const uint3 i = lucent::launch_index(), n = lucent::launch_size();
    const sample_common::PinholeCamera c = rec.camera[0u];
    fog::RadiancePayload prd{make_float3(0.0f), 0.0f, 0};
    lucent::trace(rec.top_object,
                  lucent::make_ray(c.eye, sample_common::pixel_centre_direction(c, i, n),
                                   fog::kRadianceRay, 0.0f),
                  prd);
    rec.output[make_uint2(i.x, i.y)] = make_float4(prd.color, 1.0f);
}

// The environment: an equirectangular map when given, else a procedural sky.
LUCENT_MISS(fog_environment, fog::MissRecord, fog::RadiancePayload) {
    const float3 d = normalize(lucent::current_ray().direction);
    prd.distance = 1e30f;
    if (rec.has_environment) {
        const float u = 0.5f + atan2f(d.x, -d.z) * (0.5f / 3.14159265f);
        const float v = acosf(clampf(d.y, -1.0f, 1.0f)) * (1.0f / 3.14159265f);
        prd.color = make_float3(lucent::tex2D(rec.environment, make_float2(u, v)));
        return;
    }
    const float up = d.y;
    if (up < 0.0f) {  // below the horizon: a dim ground haze
        prd.color = lerp(make_float3(0.55f, 0.55f, 0.58f), make_float3(0.2f, 0.19f, 0.18f),
                         clampf(-up * 4.0f, 0.0f, 1.0f));
        return;
    }
    const float3 horizon = make_float3(0.75f, 0.82f, 0.9f),
                 zenith = make_float3(0.2f, 0.38f, 0.75f);
    prd.color = lerp(horizon, zenith, sqrtf(up));
}

// ---- surfaces ------------------------------------------------------------------------------
// The triangles' attributes: sample_common::mesh_normal's, in fog's HitAttributes (which the
// fog box's intersection shares, with its exit distance).
LUCENT_ATTRIBUTE(fog_mesh_attributes, sample_common::MeshRecord, fog::HitAttributes) {
    const uint3 t = rec.triangles[prim];
    attr.normal =
        cross(rec.positions[t.y] - rec.positions[t.x], rec.positions[t.z] - rec.positions[t.x]);
    attr.t_exit = 0.0f;
}

LUCENT_CLOSEST_HIT(fog_phong, fog::PhongRecord, fog::RadiancePayload, fog::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    const float3 p = ray.origin + lucent::t_hit() * ray.direction;
    const float3 n =
        faceforward(normalize(lucent::object_to_world_normal(attr.normal)), ray.direction);
    const float3 origin = sample_common::offset_along_normal(p, n, rec.scene_size);
    const float3 kd = fog::pattern_colour(rec, p);
    float3 color = kd * rec.ambient;
    const fog::LightingParams params = fog::lighting(rec);
    for (unsigned l = 0; l < rec.lights.count(); ++l) {
        const fog::PointLight light = rec.lights[l];
        const float3 to = light.position - p;
        const float3 L = normalize(to);
        const float cos_l = dot(n, L);
        if (cos_l <= 0.0f) continue;
        const float3 arriving = fog::light_arriving(params, origin, to, light);
        if (max_component(arriving) <= 0.0f) continue;
        const float3 H = normalize(L - normalize(ray.direction));
        const float spec = powf(lc_max(0.0f, dot(n, H)), rec.phong_exponent);
        color += arriving * (kd * cos_l + rec.Ks * spec);
    }
    if (max_component(rec.Kr) > 0.0f && prd.depth + 1 < int(rec.max_depth)) {
        fog::RadiancePayload reflected{make_float3(0.0f), 0.0f, prd.depth + 1};
        lucent::trace(
            rec.top_object,
            lucent::make_ray(origin, reflect(normalize(ray.direction), n), fog::kRadianceRay, 0.0f),
            reflected);
        color += rec.Kr * reflected.color;
    }
    prd.color = color;
    prd.distance = lucent::t_hit();
}

// Glass: Fresnel-weighted reflection and refraction; Beer's law for the path just travelled
// inside it (the ray leaving the crystal has been inside for t_hit).
LUCENT_CLOSEST_HIT(fog_glass, fog::GlassRecord, fog::RadiancePayload, fog::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    const float3 d = normalize(ray.direction);
    const float3 p = ray.origin + lucent::t_hit() * ray.direction;
    const float3 outward = normalize(lucent::object_to_world_normal(attr.normal));
    const bool entering = dot(d, outward) < 0.0f;
    const float3 n = entering ? outward : -outward;  // faces the incoming ray
    const float eta = entering ? 1.0f / rec.ior : rec.ior;
    const float cos_i = -dot(d, n);
    const float F = fog::fresnel(cos_i, eta);
    float3 color = make_float3(0.0f);
    if (prd.depth + 1 < int(rec.max_depth)) {
        fog::RadiancePayload reflected{make_float3(0.0f), 0.0f, prd.depth + 1};
        lucent::trace(rec.top_object,
                      lucent::make_ray(sample_common::offset_along_normal(p, n, rec.scene_size),
                                       reflect(d, n), fog::kRadianceRay, 0.0f),
                      reflected);
        color += F * reflected.color;
        if (F < 1.0f) {
            const float sin2_t = eta * eta * (1.0f - cos_i * cos_i);
            const float3 t = normalize(eta * d + (eta * cos_i - sqrtf(1.0f - sin2_t)) * n);
            fog::RadiancePayload refracted{make_float3(0.0f), 0.0f, prd.depth + 1};
            lucent::trace(rec.top_object,
                          lucent::make_ray(sample_common::offset_along_normal(p, -n, rec.scene_size),
                                           t, fog::kRadianceRay, 0.0f),
                          refracted);
            color += (1.0f - F) * refracted.color;
        }
    }
    if (!entering) {  // the ray crossed the glass: Beer's law over the distance inside
        const float inside = lucent::t_hit() * length(ray.direction);
        color =
            color * make_float3(expf(-rec.extinction.x * inside), expf(-rec.extinction.y * inside),
                                expf(-rec.extinction.z * inside));
    }
    prd.color = color;
    prd.distance = lucent::t_hit();
}

LUCENT_ANY_HIT(fog_opaque_shadow, lucent::NoRecord, fog::ShadowPayload, fog::HitAttributes) {
    prd.attenuation = make_float3(0.0f);
    terminate_ray();
}

// The crystal lets a tinted part of the light through (each face it crosses).
LUCENT_ANY_HIT(fog_glass_shadow, fog::GlassRecord, fog::ShadowPayload, fog::HitAttributes) {
    prd.attenuation = prd.attenuation * rec.shadow_tint;
    if (max_component(prd.attenuation) < 1e-3f) {
        prd.attenuation = make_float3(0.0f);
        terminate_ray();
    }
    ignore_intersection();
}

// ---- the fog box ---------------------------------------------------------------------------
LUCENT_BOUNDING_BOX(fog_box_bounds, fog::FogBoxRecord) {
    box.lo = rec.box_min;
    box.hi = rec.box_max;
}

LUCENT_INTERSECTION(fog_box_intersect, fog::FogBoxRecord, fog::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    const float2 span = fog::box_span(rec.box_min, rec.box_max, ray.origin, ray.direction);
    if (span.x > span.y || span.y <= ray.tmin) return;
    // From outside: the entry point. From inside (the origin is in the fog): just past the
    // ray's start (a hit must lie beyond tmin), by a millionth of its way through the box and
    // of tmin, so at any scale as little fog is skipped and tmin is passed by some floats.
    const float t = span.x > ray.tmin
                        ? span.x
                        : ray.tmin + 1e-6f * (fabsf(ray.tmin) + (span.y - span.x));
    if (lucent::potential_intersection(t)) {
        attr.normal = make_float3(0.0f, 1.0f, 0.0f);
        attr.t_exit = span.y;
        lucent::report_intersection(0);
    }
}

// Shadows pass through fog (Sebald: "simply ignores the intersection").
LUCENT_ANY_HIT(fog_volume_shadow, lucent::NoRecord, fog::ShadowPayload, fog::HitAttributes) {
    ignore_intersection();
}

LUCENT_CLOSEST_HIT(fog_volume, fog::FogRecord, fog::RadiancePayload, fog::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    // What lies beneath: the same ray again against the solid objects alone (exactly the hits
    // of a scene without fog, so zero density reproduces it). What it hits traces its own
    // rays through the whole scene, fog and all.
    fog::RadiancePayload behind{make_float3(0.0f), 0.0f, prd.depth};
    lucent::trace(
        rec.solid_object,
        lucent::make_ray(ray.origin, ray.direction, fog::kRadianceRay, ray.tmin, ray.tmax), behind);
    const float t_start = lucent::t_hit(), t_end = lc_min(attr.t_exit, behind.distance);
    const float speed = length(ray.direction);  // t to distance
    const float distance = lc_max(0.0f, t_end - t_start) * speed;
    // March in equal steps of at most `step`, sampling each at its middle: each step's
    // transmittance is exp(-density dt), so the ray's is exp(-optical depth), the sum of
    // density dt (one exp, not one per step). The fog colour fills what it takes away.
    const unsigned steps = distance > 0.0f ? unsigned(ceilf(distance / rec.step)) : 0u;
    const float dt = steps ? distance / float(steps) : 0.0f;
    const float3 d = ray.direction * (1.0f / speed);
    const float3 start = ray.origin + t_start * ray.direction + (0.5f * dt) * d;
    // Density = density x noise(x / scale, z / scale) x falloff(y), with falloff falling
    // linearly from 1 at the bottom of the box to 0 at its top. Every term is linear in the
    // step index, so the march only adds increments.
    const float inv_scale = 1.0f / rec.noise_scale;
    float nx = (start.x - rec.model_origin.x) * inv_scale,
          nz = (start.z - rec.model_origin.z) * inv_scale;
    const float dnx = dt * d.x * inv_scale, dnz = dt * d.z * inv_scale;
    const float inv_height = 1.0f / (rec.box_max.y - rec.box_min.y);
    float fall = (rec.box_max.y - start.y) * inv_height;
    const float dfall = -dt * d.y * inv_height;
    const uint4 key = rec.noise_key;
    const unsigned rounds = rec.rounds;
    const bool noise = rec.noise != 0u, falloff = rec.falloff != 0u;
    // Past an optical depth of 9.2 less than 1e-4 of what lies behind shows through.
    const float limit = rec.density * dt > 0.0f ? 9.2f / (rec.density * dt) : 3.4e38f;
    float weight_sum = 0.0f;  // optical depth / (density dt)
    lucent::GradientCell cell;
    unsigned s = 0;
    while (s < steps && weight_sum < limit) {
        // The samples from s on that stay in one lattice cell: its gradients are fetched
        // once, and the offsets in the cell only grow by their increments (no floor per
        // sample). A run may end a rounding error past the cell's edge, where the noise
        // continues smoothly.
        unsigned run = steps - s;
        float tx = 0.0f, tz = 0.0f;
        if (noise) {
            const float x = nx + float(s) * dnx, z = nz + float(s) * dnz;
            const float fx = floorf(x), fz = floorf(z);
            cell.fetch(int(fx), int(fz), key, rounds);
            tx = x - fx;
            tz = z - fz;
            // Samples with an offset still in [0, 1): ceil((1 - t) / dt) going up,
            // floor(t / -dt) + 1 going down.
            const float kx = dnx > 0.0f   ? ceilf((1.0f - tx) / dnx)
                             : dnx < 0.0f ? floorf(tx / -dnx) + 1.0f
                                          : 3e9f;
            const float kz = dnz > 0.0f   ? ceilf((1.0f - tz) / dnz)
                             : dnz < 0.0f ? floorf(tz / -dnz) + 1.0f
                                          : 3e9f;
            const float k = lc_min(kx, kz);
            if (k < float(run)) run = lc_max(1u, unsigned(k));
        }
        float fall_s = fall + float(s) * dfall;
        if (noise) {
            // In a cell the four corner terms of the noise (gradient . offset) are linear in
            // the step too: each grows by a constant. Only the fades are evaluated anew.
            const lucent::GradientCell& c = cell;
            float n00 = c.g00.x * tx + c.g00.y * tz, n10 = c.g10.x * (tx - 1.0f) + c.g10.y * tz;
            float n01 = c.g01.x * tx + c.g01.y * (tz - 1.0f);
            float n11 = c.g11.x * (tx - 1.0f) + c.g11.y * (tz - 1.0f);
            const float d00 = c.g00.x * dnx + c.g00.y * dnz, d10 = c.g10.x * dnx + c.g10.y * dnz;
            const float d01 = c.g01.x * dnx + c.g01.y * dnz, d11 = c.g11.x * dnx + c.g11.y * dnz;
            for (unsigned i = 0; i < run; ++i) {
                const float u = lucent::quintic_fade(tx), v = lucent::quintic_fade(tz);
                const float n = lerpf(lerpf(n00, n10, u), lerpf(n01, n11, u), v);
                float w = clampf(0.5f + n * 0.70710678f, 0.0f, 1.0f);  // as tea_gradient_noise
                if (falloff) w *= clampf(fall_s, 0.0f, 1.0f);
                weight_sum += w;
                tx += dnx;
                tz += dnz;
                n00 += d00;
                n10 += d10;
                n01 += d01;
                n11 += d11;
                fall_s += dfall;
            }
        } else {
            for (unsigned i = 0; i < run; ++i) {
                weight_sum += falloff ? clampf(fall_s, 0.0f, 1.0f) : 1.0f;
                fall_s += dfall;
            }
        }
        s += run;
    }
    const float optical_depth = weight_sum * rec.density * dt;
    const float transmittance = expf(-optical_depth);
    prd.color = rec.fog_color * (1.0f - transmittance) + behind.color * transmittance;
    prd.distance = behind.distance;
}

}  // namespace fog

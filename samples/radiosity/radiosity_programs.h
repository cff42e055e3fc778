// Instant radiosity with deferred shading (the seed blog, "Instant Radiosity using OptiX and
// Deferred Rendering"): photons leave the area lights from a jittered sqrt(N) x sqrt(N) grid of
// cosine-distributed directions and bounce (with optional Russian roulette), leaving a virtual
// point light (VPL) at each hit; the host may merge the VPLs into a voxel grid; then a G-buffer
// pass and a shading pass that adds direct light and every VPL as a point light.
#pragma once

#include "lucent/device.h"
#include "samples/common/common_programs.h"

namespace radiosity {

/// The module of this sample's programs (lucent/device/module.h).
LUCENT_MODULE(radiosity, lucent::kUsesOccluded)

enum : unsigned { kRadianceRay = 0, kShadowRay = 1, kPhotonRay = 2 };
enum : unsigned { kPhotonEntry = 0, kGBufferEntry = 1, kShadeEntry = 2, kEntryCount = 3 };

using sample_common::AreaLight;  // emission: radiance

/// A virtual point light. Unmerged: a diffuse emitter, intensity power / pi x cos around
/// `normal`. Merged (VplGrid): at a cell's centre with the power-weighted mean normal, or
/// isotropic (normal zero, intensity power / 4 pi) when the cell's normals cancel out.
struct Vpl {
    float3 position;
    float3 normal;
    float3 power;  // flux leaving it
};

/// Radiant intensity of a VPL towards the unit direction w (from the VPL).
LUCENT_HD inline float3 vpl_intensity(const Vpl& vpl, float3 w) {
    if (dot(vpl.normal, vpl.normal) == 0.0f) return vpl.power * (0.25f / 3.14159265f);
    return vpl.power * (lc_max(0.0f, dot(vpl.normal, w)) / 3.14159265f);
}

/// What a triangle hit gives the hit programs (sample_common::mesh_normal_uv).
using HitAttributes = sample_common::MeshNormalUv;

struct SurfacePayload {  // radiance and photon rays: what was hit
    float3 position, normal, albedo, emission;
    float distance;  // < 0: missed
};
struct ShadowPayload {  // the shadow ray type's declared payload; lucent::occluded() uses none
    float visible;
};

/// Uniform floats in [0, 1) from TEA (Sebald's generator) keyed by a stream and an index,
/// so the CPU and GPU draw the same numbers.
LUCENT_HD inline float2 random2(unsigned stream, unsigned index) {
    const uint2 r = lucent::tea<4>(make_uint2(stream, index), lucent::zafar_tea_key());
    return make_float2(lucent::tea_unit_float(r.x), lucent::tea_unit_float(r.y));
}

using sample_common::cosine_direction;

struct SurfaceRecord {
    float3 Kd, Ke;
    lucent::TextureView diffuse_map;  // multiplies Kd; a white texel when there is none
};
LUCENT_RECORD(SurfaceRecord, Kd, Ke, diffuse_map)

struct PhotonRecord {
    lucent::BufferView<AreaLight> area_lights;
    lucent::BufferView<const float> area_light_cdf;  // each light's share of the photons: its power
    lucent::BufferView<Vpl> vpls;  // photons x bounces slots; unused ones have zero power
    unsigned bounces;
    unsigned roulette;  // 1: Russian roulette after the first bounce
    float vpl_offset;   // how far back along the ray a VPL sits from its hit
    float scene_size;   // of its bounds: sample_common::offset_ray_origin
    lucent::Handle top_object;
};
LUCENT_RECORD(PhotonRecord, area_lights, area_light_cdf, vpls, bounces, roulette, vpl_offset, scene_size,
              top_object)

struct GBufferRecord {
    lucent::BufferView<sample_common::PinholeCamera> camera;  // one element
    lucent::BufferView<float4> gbuffer_position;  // xyz, w = distance (< 0: background)
    lucent::BufferView<float4> gbuffer_normal;
    lucent::BufferView<float4> gbuffer_albedo;
    lucent::BufferView<float4> gbuffer_emission;
    lucent::Handle top_object;
};
LUCENT_RECORD(GBufferRecord, camera, gbuffer_position, gbuffer_normal, gbuffer_albedo,
              gbuffer_emission, top_object)

struct ShadeRecord {
    lucent::BufferView<sample_common::PinholeCamera> camera;  // the G-buffer's
    lucent::BufferView<float4> gbuffer_position, gbuffer_normal, gbuffer_albedo, gbuffer_emission;
    lucent::BufferView<float4> output;
    lucent::BufferView<AreaLight> area_lights;
    unsigned area_samples;  // per light and pixel: a stratified side x side grid
    lucent::BufferView<Vpl> vpls;
    unsigned gi;           // 0: direct light only
    unsigned vpl_shadows;  // 1: a shadow ray per VPL (the blog had none)
    unsigned show_vpls;    // 1: draw each VPL as a dot
    float clamp_distance;  // VPL distances below it count as it (bounds the 1/d^2 spike)
    float dot_radius;      // show_vpls: angular radius of a dot, radians
    float scene_size;      // of its bounds: sample_common::offset_ray_origin
    lucent::Handle top_object;
};
LUCENT_RECORD(ShadeRecord, camera, gbuffer_position, gbuffer_normal, gbuffer_albedo, gbuffer_emission,
              output, area_lights, area_samples, vpls, gi, vpl_shadows, show_vpls, clamp_distance,
              dot_radius, scene_size, top_object)

/// Nothing between `from` and just short of `to`, both off their surfaces
/// (sample_common::offset_ray_origin; a VPL is, by vpl_offset): an occlusion query, no programs.
LUCENT_HD inline bool visible(const ShadeRecord& rec, float3 from, float3 to) {
    return !lucent::occluded(rec.top_object, sample_common::segment_ray(from, to, kShadowRay));
}

LUCENT_HD inline float3 xyz(float4 v) {
    return make_float3(v.x, v.y, v.z);
}

/// Irradiance at x (normal n) from the area lights: side x side stratified samples each,
/// jittered per pixel, with shadow rays.
LUCENT_HD inline float3 direct_irradiance(const ShadeRecord& rec, float3 x, float3 n,
                                          unsigned pixel) {
    float3 sum = make_float3(0.0f);
    const unsigned side = rec.area_samples > 1 ? unsigned(sqrtf(float(rec.area_samples))) : 1u;
    for (unsigned l = 0; l < rec.area_lights.count(); ++l) {
        const AreaLight light = rec.area_lights[l];
        const float area = sample_common::light_area(light);
        const float3 light_normal = sample_common::light_normal(light);
        for (unsigned s = 0; s < side * side; ++s) {
            const float2 r = random2(pixel, s * 64u + l);
            const float u = (float(s % side) + r.x) / float(side);
            const float v = (float(s / side) + r.y) / float(side);
            const float3 q = sample_common::light_point(light, u, v);
            const float3 to = q - x;
            const float d2 = dot(to, to), d = sqrtf(d2);
            const float cos_x = dot(n, to) / d, cos_light = -dot(light_normal, to) / d;
            if (cos_x > 0.0f && cos_light > 0.0f &&
                visible(rec, x, sample_common::offset_ray_origin(q, light_normal, rec.scene_size)))
                sum += light.emission * (cos_x * cos_light / d2 * area / float(side * side));
        }
    }
    return sum;
}

/// Irradiance at x (normal n) from every VPL as a point light, 1/d^2 bounded by the clamp.
LUCENT_HD inline float3 vpl_irradiance(const ShadeRecord& rec, float3 x, float3 n) {
    float3 sum = make_float3(0.0f);
    const float clamp2 = rec.clamp_distance * rec.clamp_distance;
    for (unsigned k = 0; k < rec.vpls.count(); ++k) {
        const Vpl vpl = rec.vpls[k];
        if (max_component(vpl.power) <= 0.0f) continue;
        const float3 to = vpl.position - x;
        const float d2 = dot(to, to), d = sqrtf(d2);
        const float cos_x = dot(n, to) / d;
        if (cos_x <= 0.0f) continue;
        const float3 intensity = vpl_intensity(vpl, -to / d);
        if (max_component(intensity) <= 0.0f) continue;
        if (rec.vpl_shadows && !visible(rec, x, vpl.position)) continue;
        sum += intensity * (cos_x / lc_max(d2, clamp2));
    }
    return sum;
}


// ---- photons from the area lights ----------------------------------------------------------
LUCENT_RAY_GENERATION(radiosity_photons, radiosity::PhotonRecord) {
    const uint3 i = lucent::launch_index(), n = lucent::launch_size();
    const unsigned photon = (i.z * n.y + i.y) * n.x + i.x;
    for (unsigned b = 0; b < rec.bounces; ++b)
        rec.vpls[photon * rec.bounces + b] = radiosity::Vpl{};
    // The light in proportion to its power (one light: always it), so that every photon
    // carries about the same flux whatever the number of emitters.
    const unsigned l =
        sample_common::pick_light(rec.area_light_cdf, radiosity::random2(photon, 0x53u).x);
    const radiosity::AreaLight light = rec.area_lights[l];
    const float area = sample_common::light_area(light);
    const float3 light_normal = sample_common::light_normal(light);
    // A uniform point on the light; the direction from the jittered grid cell (x, y) of the
    // cosine-distributed hemisphere, as the blog's generateHemisphereLightPhoton.
    const float2 at = radiosity::random2(photon, 0x51u);
    const float2 jitter = radiosity::random2(photon, 0x52u);
    float3 origin = sample_common::offset_ray_origin(sample_common::light_point(light, at.x, at.y),
                                                     light_normal, rec.scene_size);
    float3 direction = radiosity::cosine_direction(
        light_normal, (float(i.x) + jitter.x) / float(n.x), (float(i.y) + jitter.y) / float(n.y));
    // The light's flux pi L A over the expected number of its photons, n.x n.y p(l).
    float3 flux = light.emission *
                  (3.14159265f * area /
                   (float(n.x * n.y) * sample_common::light_probability(rec.area_light_cdf, l)));
    for (unsigned b = 0; b < rec.bounces; ++b) {
        radiosity::SurfacePayload hit{};
        hit.distance = -1.0f;
        lucent::trace(rec.top_object,
                      lucent::make_ray(origin, direction, radiosity::kPhotonRay, 0.0f),
                      hit);
        if (hit.distance < 0.0f || max_component(hit.albedo) <= 0.0f) break;
        // The VPL: a little back along the ray, so it lies in front of its surface.
        const float3 power = flux * hit.albedo;
        const float back = lc_min(rec.vpl_offset, 0.5f * hit.distance);
        rec.vpls[photon * rec.bounces + b] =
            radiosity::Vpl{hit.position - back * direction, hit.normal, power};
        if (b + 1 == rec.bounces) break;
        flux = power;  // cosine sampling of the Lambertian bounce cancels cos / pi
        const float2 r = radiosity::random2(photon, 0x100u + b);
        if (rec.roulette && b > 0) {
            // Survive with the albedo's largest component; the survivors carry the rest.
            const float survive = lc_min(1.0f, max_component(hit.albedo));
            if (radiosity::random2(photon, 0x200u + b).x >= survive) break;
            flux = flux * (1.0f / survive);
        }
        origin = sample_common::offset_ray_origin(hit.position, hit.normal, rec.scene_size);
        direction = radiosity::cosine_direction(hit.normal, r.x, r.y);
    }
}

// ---- the G-buffer: what each pixel sees ----------------------------------------------------
LUCENT_RAY_GENERATION(radiosity_gbuffer, radiosity::GBufferRecord) {
    const uint3 p = lucent::launch_index(), n = lucent::launch_size();
    const sample_common::PinholeCamera c = rec.camera[0u];
    radiosity::SurfacePayload hit{};
    hit.distance = -1.0f;
    lucent::trace(rec.top_object,
                  lucent::make_ray(c.eye, sample_common::pixel_centre_direction(c, p, n),
                                   radiosity::kRadianceRay, 0.0f),
                  hit);
    const uint2 pixel = make_uint2(p.x, p.y);
    rec.gbuffer_position[pixel] = make_float4(hit.position, hit.distance);
    rec.gbuffer_normal[pixel] = make_float4(hit.normal, 0.0f);
    rec.gbuffer_albedo[pixel] = make_float4(hit.albedo, 0.0f);
    rec.gbuffer_emission[pixel] = make_float4(hit.emission, 0.0f);
}

// Radiance and photon rays both want the surface; the normal faces where the ray came from.
LUCENT_CLOSEST_HIT(radiosity_surface, radiosity::SurfaceRecord, radiosity::SurfacePayload,
                   radiosity::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    prd.position = ray.origin + lucent::t_hit() * ray.direction;
    prd.normal = faceforward(normalize(lucent::object_to_world_normal(attr.geometric_normal)),
                             ray.direction);
    prd.albedo = rec.Kd * sample_common::diffuse_texel(rec.diffuse_map, attr.uv);
    prd.emission = rec.Ke;
    prd.distance = lucent::t_hit();
}

// ---- deferred shading: direct light plus every VPL -----------------------------------------
LUCENT_RAY_GENERATION(radiosity_shade, radiosity::ShadeRecord) {
    const uint3 p = lucent::launch_index(), n = lucent::launch_size();
    const uint2 pixel = make_uint2(p.x, p.y);
    const float4 position = rec.gbuffer_position[pixel];
    float3 color = make_float3(0.0f);
    if (position.w >= 0.0f) {
        const float3 x = radiosity::xyz(position), nx = radiosity::xyz(rec.gbuffer_normal[pixel]);
        const float3 origin = sample_common::offset_ray_origin(x, nx, rec.scene_size);
        float3 irradiance = radiosity::direct_irradiance(rec, origin, nx, p.y * n.x + p.x);
        if (rec.gi) irradiance += radiosity::vpl_irradiance(rec, origin, nx);
        color = radiosity::xyz(rec.gbuffer_emission[pixel]) +
                radiosity::xyz(rec.gbuffer_albedo[pixel]) * (1.0f / 3.14159265f) * irradiance;
    }
    if (rec.show_vpls && position.w >= 0.0f) {
        // A VPL in front of what the pixel sees, within the dot's angular radius of its ray:
        // drawn in its own colour at full brightness.
        const float3 eye = rec.camera[0u].eye;
        const float3 ray = radiosity::xyz(position) - eye;
        const float seen = length(ray), cos_radius = cosf(rec.dot_radius);
        for (unsigned k = 0; k < rec.vpls.count(); ++k) {
            const radiosity::Vpl vpl = rec.vpls[k];
            const float peak = max_component(vpl.power);
            if (peak <= 0.0f) continue;
            const float3 to = vpl.position - eye;
            const float d = length(to);
            if (d < seen && dot(to / d, ray / seen) > cos_radius) color = vpl.power / peak;
        }
    }
    rec.output[pixel] = make_float4(color, 1.0f);
}

}  // namespace radiosity

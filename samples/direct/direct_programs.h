// Direct lighting of any scene (scene/scene.h): Lambertian surfaces with emission, point
// lights and parallelogram area lights, with shadow rays. The building block of the global
// illumination samples, and a quick look at a scene file on either backend.
#pragma once

#include "lucent/device.h"
#include "samples/common/common_programs.h"

namespace direct {

/// The module of this sample's programs (lucent/device/module.h).
LUCENT_MODULE(direct, lucent::kUsesOccluded)

struct RadiancePayload {
    float3 color;
};
struct ShadowPayload {  // the shadow ray type's declared payload; lucent::occluded() uses none
    float visible;
};

using sample_common::AreaLight;
using sample_common::PointLight;

enum : unsigned { kRadianceRay = 0, kShadowRay = 1 };

/// What a triangle hit gives the hit programs (sample_common::mesh_normal_uv): its normal
/// and its texture coordinate.
using HitAttributes = sample_common::MeshNormalUv;

struct CameraRecord {
    lucent::BufferView<sample_common::PinholeCamera> camera;  // one element
    lucent::BufferView<float4> output;
    lucent::Handle top_object;
};
LUCENT_RECORD(CameraRecord, camera, output, top_object)

struct SurfaceRecord {
    float3 Kd, Ke;
    lucent::TextureView diffuse_map;  // multiplies Kd; a 1x1 white texel when there is none
    lucent::BufferView<PointLight> point_lights;
    lucent::BufferView<AreaLight> area_lights;
    unsigned area_samples;  // per area light: a stratified sqrt(n) x sqrt(n) grid
    float scene_size;  // of its bounds: sample_common::offset_ray_origin
    lucent::Handle top_object;
    // A scene without lights: a point light of this intensity at the camera's eye (zero:
    // none), which sees every point the camera's rays hit, so it needs no shadow ray.
    float3 headlight;
    lucent::BufferView<const sample_common::PinholeCamera> camera;
};
LUCENT_RECORD(SurfaceRecord, Kd, Ke, diffuse_map, point_lights, area_lights, area_samples,
              scene_size, top_object, headlight, camera)

struct MissRecord {
    float3 background;
};
LUCENT_RECORD(MissRecord, background)

/// Fraction of light from `origin` (a hit point moved off its surface) that reaches `target`
/// (a point light, or a point of an area light moved off it towards `origin`): 0 or 1, an
/// occlusion query (every surface is opaque).
LUCENT_HD inline float visibility(const SurfaceRecord& rec, float3 origin, float3 target) {
    return lucent::occluded(rec.top_object, sample_common::segment_ray(origin, target, kShadowRay))
               ? 0.0f
               : 1.0f;
}


LUCENT_RAY_GENERATION(direct_camera, direct::CameraRecord) {
    const uint3 i = lucent::launch_index(), n = lucent::launch_size();
    const sample_common::PinholeCamera c = rec.camera[0u];
    direct::RadiancePayload prd{make_float3(0.0f)};
    lucent::trace(rec.top_object,
                  lucent::make_ray(c.eye, sample_common::pixel_centre_direction(c, i, n),
                                   direct::kRadianceRay, 0.0f),
                  prd);
    rec.output[make_uint2(i.x, i.y)] = make_float4(prd.color, 1.0f);
}

LUCENT_MISS(direct_miss, direct::MissRecord, direct::RadiancePayload) {
    prd.color = rec.background;
}

LUCENT_CLOSEST_HIT(direct_lambert, direct::SurfaceRecord, direct::RadiancePayload,
                   direct::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    const float3 p = ray.origin + lucent::t_hit() * ray.direction;
    const float3 n = faceforward(normalize(lucent::object_to_world_normal(attr.geometric_normal)),
                                 ray.direction);
    const float3 origin = sample_common::offset_ray_origin(p, n, rec.scene_size);
    float3 color = rec.Ke;
    const float3 texel = sample_common::diffuse_texel(rec.diffuse_map, attr.uv);
    const float3 albedo = rec.Kd * texel * (1.0f / 3.14159265f);  // Lambert: rho / pi
    for (unsigned l = 0; l < rec.point_lights.count(); ++l) {
        const direct::PointLight light = rec.point_lights[l];
        const float3 to = light.position - p;
        const float d2 = dot(to, to), cos_theta = dot(n, to) / sqrtf(d2);
        if (cos_theta > 0.0f)
            color += albedo * light.intensity *
                     (cos_theta / d2 * direct::visibility(rec, origin, light.position));
    }
    if (max_component(rec.headlight) > 0.0f) {
        const float3 to = rec.camera[0u].eye - p;
        const float d2 = dot(to, to), cos_theta = dot(n, to) / sqrtf(d2);
        if (cos_theta > 0.0f) color += albedo * rec.headlight * (cos_theta / d2);
    }
    // Area lights: a stratified grid of points, one shadow ray each (TEA jitter per pixel).
    const uint3 index = lucent::launch_index();
    const unsigned side = rec.area_samples > 1 ? unsigned(sqrtf(float(rec.area_samples))) : 1u;
    for (unsigned l = 0; l < rec.area_lights.count(); ++l) {
        const direct::AreaLight light = rec.area_lights[l];
        const float area = sample_common::light_area(light);
        const float3 light_normal = sample_common::light_normal(light);
        float3 sum = make_float3(0.0f);
        for (unsigned s = 0; s < side * side; ++s) {
            const uint2 r = lucent::tea<4>(make_uint2(index.y * 65536u + index.x, s * 16u + l),
                                           lucent::zafar_tea_key());
            const float u = (float(s % side) + lucent::tea_unit_float(r.x)) / float(side);
            const float v = (float(s / side) + lucent::tea_unit_float(r.y)) / float(side);
            const float3 q = sample_common::light_point(light, u, v);
            const float3 to = q - p;
            const float d2 = dot(to, to), d = sqrtf(d2);
            // One-sided: the light emits towards cross(edge1, edge2) (scene.h).
            const float cos_surface = dot(n, to) / d, cos_light = -dot(light_normal, to) / d;
            if (cos_surface > 0.0f && cos_light > 0.0f)
                sum += light.emission *
                       (cos_surface * cos_light / d2 *
                        direct::visibility(rec, origin,
                                           sample_common::offset_ray_origin(q, light_normal,
                                                                            rec.scene_size)));
        }
        color += albedo * sum * (area / float(side * side));
    }
    prd.color = color;
}

}  // namespace direct

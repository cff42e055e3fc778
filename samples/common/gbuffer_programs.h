// The G-buffer pass every sample can launch for --aov and --denoise: one primary ray per
// pixel, through the pixel's centre, of a ray type of its own; the closest hit writes the
// surface's albedo (Kd times its diffuse map), its normal facing the camera, its world
// position, its camera-space depth and its instance index. The sample adds gbuffer_hit to
// each of its materials for that ray type (samples/gbuffer.h), so the pass sees the sample's
// own scene graph and its own Kd and diffuse_map variables.
#pragma once

#include "lucent/device.h"
#include "samples/common/common_programs.h"

namespace sample_gbuffer {

/// The module of the G-buffer programs (lucent/device/module.h).
LUCENT_MODULE(sample_gbuffer)

/// What the closest hit hands back to the pass.
struct GBufferPayload {
    float3 albedo;
    float3 normal;    // world space, unit, facing the ray's origin
    float t;          // along the unit primary direction
    unsigned instance;
    unsigned hit;     // 0 on a miss
};

struct CameraRecord {
    lucent::BufferView<const sample_common::PinholeCamera> camera;  // one element
    lucent::Handle top_object;
    unsigned gbuffer_ray_type;
    lucent::BufferView<float4> aov_albedo;    // rgb; a = coverage (1 hit, 0 background)
    lucent::BufferView<float4> aov_normal;    // xyz; w = the instance index (-1 background)
    lucent::BufferView<float4> aov_position;  // xyz world; w = camera-space depth (0 background)
};
LUCENT_RECORD(CameraRecord, camera, top_object, gbuffer_ray_type, aov_albedo, aov_normal,
              aov_position)

struct SurfaceRecord {
    float3 Kd;
    lucent::TextureView diffuse_map;
    unsigned gbuffer_instance;  // set on each GeometryInstance by mesh_group
};
LUCENT_RECORD(SurfaceRecord, Kd, diffuse_map, gbuffer_instance)

LUCENT_RAY_GENERATION(gbuffer_camera, sample_gbuffer::CameraRecord) {
    const uint3 i = lucent::launch_index(), n = lucent::launch_size();
    const uint2 pixel = make_uint2(i.x, i.y);
    const sample_common::PinholeCamera camera = rec.camera[0u];
    const float3 direction = sample_common::pixel_centre_direction(camera, i, n);
    GBufferPayload prd;
    prd.hit = 0;
    lucent::trace(rec.top_object, lucent::make_ray(camera.eye, direction, rec.gbuffer_ray_type, 0.0f),
                  prd);
    if (!prd.hit) {
        rec.aov_albedo[pixel] = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
        rec.aov_normal[pixel] = make_float4(0.0f, 0.0f, 0.0f, -1.0f);
        rec.aov_position[pixel] = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
        return;
    }
    const float3 x = camera.eye + prd.t * direction;
    // Camera-space z: the distance along the view axis W (OpenEXR's "Z", pbrt-v4's p.z).
    const float depth = prd.t * dot(direction, normalize(camera.W));
    rec.aov_albedo[pixel] = make_float4(prd.albedo, 1.0f);
    rec.aov_normal[pixel] = make_float4(prd.normal, float(prd.instance));
    rec.aov_position[pixel] = make_float4(x, depth);
}

LUCENT_MISS(gbuffer_miss, lucent::NoRecord, sample_gbuffer::GBufferPayload) {
    prd.hit = 0;
}

LUCENT_CLOSEST_HIT(gbuffer_hit, sample_gbuffer::SurfaceRecord, sample_gbuffer::GBufferPayload,
                   sample_common::MeshNormalUv) {
    const lucent::Ray& ray = lucent::current_ray();
    const float3 ng = normalize(lucent::object_to_world_normal(attr.geometric_normal));
    prd.normal = dot(ng, ray.direction) < 0.0f ? ng : -ng;
    prd.albedo = rec.Kd * sample_common::diffuse_texel(rec.diffuse_map, attr.uv);
    prd.t = lucent::t_hit();
    prd.instance = rec.gbuffer_instance;
    prd.hit = 1;
}

}  // namespace sample_gbuffer

// The hair sample's closest hits: the path tracer's materials (pathtracer::shade, its BSDFs,
// next-event estimation and MIS) on triangles, built-in spheres and built-in curves, with
// light linking through visibility masks: each light's shadow rays carry a ray mask of their
// own (`light_masks`), so a light can ignore what an object's instance mask excludes (the
// hair casts no shadow from the key light: shadow linking, as other renderers call it).
// The camera and miss programs are the path tracer's own (pathtracer::pt_camera, pt_miss).
#pragma once

#include "lucent/device.h"
#include "samples/common/common_programs.h"
#include "samples/pathtracer/pathtracer_programs.h"

namespace hair_sample {

/// The module of this sample's programs: its shadow rays pass a visibility mask.
LUCENT_MODULE(hair_sample, lucent::kUsesOccluded, lucent::kUsesRayFlags)

/// The instance masks of the scene (8 bits, lucent's visibility masks): everything but the
/// hair, and the hair. A shadow ray's mask says which of them can block it.
enum : unsigned { kSceneMask = 1u << 0, kHairMask = 1u << 1 };

/// The path tracer's surface record (pathtracer::SurfaceRecord's fields) and each light's
/// shadow-ray mask, area lights first, then point lights.
struct LinkedSurfaceRecord {
    float3 Kd, Ks, Ke;
    lucent::TextureView diffuse_map, specular_map;
    float alpha, ior;
    lucent::BufferView<sample_common::AreaLight> area_lights;
    lucent::BufferView<const float> area_light_cdf;
    lucent::BufferView<sample_common::PointLight> point_lights;
    float scene_size;
    lucent::Handle top_object;
    lucent::BufferView<const unsigned> light_masks;
};
LUCENT_RECORD(LinkedSurfaceRecord, Kd, Ks, Ke, diffuse_map, specular_map, alpha, ior, area_lights,
              area_light_cdf, point_lights, scene_size, top_object, light_masks)

/// The shadow test of pathtracer::next_event with light linking: light `light`'s shadow
/// ray sees only the instances whose mask shares a bit with the light's.
struct LinkedShadows {
    lucent::BufferView<const unsigned> light_masks;
    LUCENT_HD bool operator()(const pathtracer::SurfaceRecord& rec, float3 from, float3 to,
                              unsigned light) const {
        return !lucent::occluded(
            rec.top_object, sample_common::segment_ray(from, to, pathtracer::kShadowRay),
            lucent::Occlusion::kExact, lucent::kRayFlagNone, light_masks[light]);
    }
};

/// Shades a hit of any primitive with BSDF `Kind`: its object-space normal (uv 0 where the
/// primitive has no texture coordinates), the path tracer's shading, linked shadows.
template <unsigned Kind>
LUCENT_HD inline void shade_linked(const LinkedSurfaceRecord& r, pathtracer::PathPayload& prd,
                                   float3 normal, float2 uv) {
    const pathtracer::SurfaceRecord surface{r.Kd,           r.Ks,           r.Ke,
                                            r.diffuse_map,  r.specular_map, r.alpha,
                                            r.ior,          r.area_lights,  r.area_light_cdf,
                                            r.point_lights, r.scene_size,   r.top_object};
    pathtracer::shade<Kind>(surface, prd, sample_common::MeshNormalUv{normal, uv},
                            LinkedShadows{r.light_masks});
}

// One closest hit per (primitive, BSDF) the scene uses: triangles (the ground, the head, the
// light's emitter: Lambert with Ke) read the mesh attribute program's normal and uv,
// built-in spheres and curves their own attributes' normal.
LUCENT_CLOSEST_HIT(linked_mesh_lambert, LinkedSurfaceRecord, pathtracer::PathPayload,
                   sample_common::MeshNormalUv) {
    shade_linked<pathtracer::kLambert>(rec, prd, attr.geometric_normal, attr.uv);
}
LUCENT_CLOSEST_HIT(linked_sphere_metal, LinkedSurfaceRecord, pathtracer::PathPayload,
                   lucent::BuiltinSphereAttributes) {
    shade_linked<pathtracer::kMetal>(rec, prd, attr.normal, make_float2(0.0f, 0.0f));
}
LUCENT_CLOSEST_HIT(linked_sphere_glass, LinkedSurfaceRecord, pathtracer::PathPayload,
                   lucent::BuiltinSphereAttributes) {
    shade_linked<pathtracer::kDielectric>(rec, prd, attr.normal, make_float2(0.0f, 0.0f));
}
LUCENT_CLOSEST_HIT(linked_sphere_coated, LinkedSurfaceRecord, pathtracer::PathPayload,
                   lucent::BuiltinSphereAttributes) {
    shade_linked<pathtracer::kCoated>(rec, prd, attr.normal, make_float2(0.0f, 0.0f));
}
/// Hair: the coated BSDF, a pigmented Lambert base under a rough clear coat, stands in
/// for a hair BSDF (Marschner et al. 2003): the coat gives the uncoloured highlight of the
/// cuticle's surface reflection (R), the base the coloured light that passed through the
/// fibre (TT, TRT), without their shifted cones. uv: the segment's parameter, 0.
LUCENT_CLOSEST_HIT(linked_curve_coated, LinkedSurfaceRecord, pathtracer::PathPayload,
                   lucent::BuiltinCurveAttributes) {
    shade_linked<pathtracer::kCoated>(rec, prd, attr.normal, make_float2(attr.u, 0.0f));
}

}  // namespace hair_sample

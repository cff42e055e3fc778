// Instant Global Illumination (Marques and Santos, §4): virtual point lights (VPLs) from
// particles traced out of the lights along Halton paths; per pixel, direct light and a
// Whitted tree of specular reflections; indirect diffuse light from the VPLs by Eq. (1) with
// the bounded geometry term. As in the paper's Fig. 3 the indirect term of the primary hit
// is a stage of its own (at 1/N resolution, with interleaved VPL subsets), merged by the
// discontinuity buffer, upsampled by Eq. (2) and composed with the direct image; hits further
// down the specular tree get their indirect inline.
//
// Beyond the paper: with the reflection layer (option reflection_layer=1) the hit of the first
// specular bounce is separated too, as the paper's §4 suggests ("storing the hitpoints on a
// buffer") and its conclusion asks for ("improving such secondary irradiance calculations"):
// the G-buffer and the indirect images get a second layer (z = 1) holding that hit, weighted
// by the mirror's Ks, and every indirect pass runs over both layers, so downsampling and
// interleaving apply to reflected surfaces as well. Deeper hits stay inline.
#pragma once

#include "lucent/device.h"
#include "samples/common/common_programs.h"
#include "samples/common/fresnel.h"

namespace igi {

/// The module of this sample's programs (lucent/device/module.h).
LUCENT_MODULE(igi, lucent::kUsesOccluded)

enum : unsigned {
    kRadianceRay = 0,
    kShadowRay = 1,
    kParticleRay = 2,
    kVplShadowRay = 3,
    kVplDepthRay = 4,  // from a VPL to the first surface: its visibility map's texels
};

/// The passes of a frame, one entry point each (IGI paper, Fig. 3).
enum : unsigned {
    kDirectEntry = 0,         // full resolution: direct + specular, and the G-buffer
    kVplEntry = 1,            // one thread per light path
    kIndirectEntry = 2,       // Eq. (1) at the primary hits, 1/N resolution, interleaved
    kDiscontinuityEntry = 3,  // merges the interleaved VPL subsets (IGI paper §4.3)
    kUpsampleEntry = 4,       // joint bilateral upsampling, Eq. (2) (IGI paper §4.2)
    kComposeEntry = 5,        // direct + rho / pi x indirect irradiance
    kIndirectSumEntry = 6,    // adds up the indirect pass's VPL slices
    kVplMapEntry = 7,         // imperfect visibility by maps: each VPL's depth map
    kEntryCount = 8
};

/// A light the particles start from and the direct stage samples. Isotropic when `normal`
/// is zero; otherwise a cosine lobe around `normal` (a piece of an area light), whose
/// intensity along the normal is `intensity`.
struct PointEmitter {
    float3 position;
    float3 intensity;
    float3 normal;
};

LUCENT_HD inline bool is_oriented(const PointEmitter& light) {
    return dot(light.normal, light.normal) > 0.0f;
}

/// Radiant intensity of `light` towards the unit direction `w` (from the light).
LUCENT_HD inline float3 intensity_towards(const PointEmitter& light, float3 w) {
    if (!is_oriented(light)) return light.intensity;
    return light.intensity * lc_max(0.0f, dot(light.normal, w));
}

/// Total flux: 4 pi I for an isotropic light, pi I for a cosine lobe.
LUCENT_HD inline float3 flux(const PointEmitter& light) {
    return light.intensity * (is_oriented(light) ? 3.14159265f : 4.0f * 3.14159265f);
}

/// A VPL: where a light path met a diffuse surface, and Le,k of Eq. (1): the flux that
/// arrived there times rho / pi (it reflects diffusely).
struct Vpl {
    float3 position;
    float3 normal;
    float3 radiance;
};

/// What a triangle hit gives the hit programs (sample_common::mesh_normal_uv): the normal
/// and the diffuse map's texture coordinate.
using HitAttributes = sample_common::MeshNormalUv;

/// Which light path starts where: its emitter, its index in that emitter's own Halton
/// sequence (from 1), and the flux it carries (the emitter's over its paths). The host
/// shares the paths among the emitters in proportion to their flux (igi.cpp).
struct LightPath {
    unsigned emitter, sequence;
    float3 flux;
};

/// One layer of the G-buffer of Fig. 3 at a hit: position, normal, the weight of its
/// irradiance in the pixel (rho for the primary hit, Ks rho for a reflected one) and the
/// distance along the eye path (< 0: no hit).
struct Surfel {
    float3 position, normal, albedo;
    float distance;
};

/// The radiance ray's payload. Where `separate` is set (the primary hit, and with the
/// reflection layer the first hit a mirror reflects) the closest hit leaves the indirect term
/// out and hands the G-buffer layer back instead: `surfel` for its own hit, `reflected` for
/// the hit of its reflection ray (depth 0 only).
struct RadiancePayload {
    float3 color;
    int depth;
    unsigned separate;  // 1: hand the G-buffer layer back; 0: the indirect term inline
    Surfel surfel, reflected;
};
/// The shadow ray types' declared payload: their rays go through lucent::occluded(), which
/// runs no program and carries none.
struct ShadowPayload {
    float visible;
};
/// The depth ray's payload: the distance to the first surface (a large number on a miss).
struct DepthPayload {
    float distance;
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

using sample_common::cosine_direction;

/// Fractional part, for Cranley-Patterson rotations of a Halton point.
LUCENT_HD inline float wrap01(float x) {
    return x - floorf(x);
}

// ---- records ---------------------------------------------------------------------------
struct GenerateRecord {
    lucent::BufferView<const PointEmitter> lights;
    lucent::BufferView<const LightPath> light_paths;  // one per path
    lucent::BufferView<Vpl> vpls;  // paths x bounces slots; unused ones have zero radiance
    unsigned bounces;
    float scene_size;  // of its bounds: sample_common::offset_ray_origin
    lucent::Handle top_object;
};
LUCENT_RECORD(GenerateRecord, lights, light_paths, vpls, bounces, scene_size, top_object)

/// The full-resolution G-buffer of the direct stage (IGI paper, Fig. 3): position (w: the distance
/// along the eye path, < 0: no hit), normal and the irradiance's weight, each image width x
/// height x layers: layer 0 the primary hits, layer 1 (with the reflection layer) the first
/// reflected hits.
struct CameraRecord {
    lucent::BufferView<sample_common::PinholeCamera> camera;  // one element
    lucent::BufferView<float4> direct;  // direct + specular (+ inline indirect below the tree)
    lucent::BufferView<float4> gbuffer_position, gbuffer_normal, gbuffer_albedo;
    lucent::Handle top_object;
};
LUCENT_RECORD(CameraRecord, camera, direct, gbuffer_position, gbuffer_normal, gbuffer_albedo,
              top_object)

/// What Eq. (1) needs wherever it is evaluated: the VPLs and how to test their visibility.
struct IndirectParams {
    lucent::BufferView<const Vpl> vpls;
    float min_d;  // Eq. (1)'s bounding distance
    float scene_size;  // of its bounds: sample_common::offset_ray_origin
    lucent::Handle top_object;
    unsigned imperfect_visibility;  // kExactVisibility ... kVisibilityMapVisibility
    lucent::Handle vpl_shadow_object;
    lucent::BufferView<const float> vpl_maps;  // size x size x VPLs (kVisibilityMapVisibility)
};

struct SurfaceRecord {
    float3 Kd, Ks, Ke;
    lucent::TextureView diffuse_map;  // multiplies Kd; a 1x1 white texel when there is none
    float ior;  // > 0: a smooth dielectric of this index (Fresnel reflection and refraction)
    lucent::BufferView<const PointEmitter> lights;
    lucent::BufferView<const Vpl> vpls;
    float min_d;
    unsigned max_depth;
    float scene_size;  // of its bounds: sample_common::offset_ray_origin
    lucent::Handle top_object;
    unsigned imperfect_visibility;
    lucent::Handle vpl_shadow_object;
    lucent::BufferView<const float> vpl_maps;
    unsigned reflection_layer;  // 1: the first reflected hit is G-buffer layer 1
};
LUCENT_RECORD(SurfaceRecord, Kd, Ks, Ke, diffuse_map, ior, lights, vpls, min_d, max_depth, scene_size, top_object,
              imperfect_visibility, vpl_shadow_object, vpl_maps, reflection_layer)

// The passes below run over launch_index().z, the G-buffer layer; their images have as many.
// The indirect pass alone splits each layer's VPLs into `slices` (its z is layer x slices +
// slice), so that a low-resolution image still gives the GPU enough threads; the sum pass
// then adds the slices up.
struct IndirectRecord {
    lucent::BufferView<const float4> gbuffer_position, gbuffer_normal;
    lucent::BufferView<float4> indirect;  // 1/downsample resolution: irradiance, w = 1 if valid
    lucent::BufferView<const Vpl> vpls;
    unsigned downsample, interleave, slices;
    float min_d;
    float scene_size;  // of its bounds: sample_common::offset_ray_origin
    lucent::Handle top_object;
    unsigned imperfect_visibility;
    lucent::Handle vpl_shadow_object;
    lucent::BufferView<const float> vpl_maps;
};
LUCENT_RECORD(IndirectRecord, gbuffer_position, gbuffer_normal, indirect, vpls, downsample,
              interleave, slices, min_d, scene_size, top_object, imperfect_visibility,
              vpl_shadow_object, vpl_maps)

/// The visibility maps of imperfect visibility by maps: for each VPL, the distance from it
/// to the first surface in each texel's direction of its hemisphere (vpl_map_direction).
struct VplMapRecord {
    lucent::BufferView<const Vpl> vpls;
    lucent::BufferView<float> vpl_maps;  // size x size x VPLs
    lucent::Handle top_object;
};
LUCENT_RECORD(VplMapRecord, vpls, vpl_maps, top_object)

struct IndirectSumRecord {
    lucent::BufferView<const float4> indirect_slices;  // layers x slices deep
    lucent::BufferView<float4> indirect;               // layers deep
    unsigned slices;
};
LUCENT_RECORD(IndirectSumRecord, indirect_slices, indirect, slices)

struct DiscontinuityRecord {
    lucent::BufferView<const float4> gbuffer_position, gbuffer_normal;
    lucent::BufferView<const float4> indirect;  // both at 1/downsample resolution
    lucent::BufferView<float4> merged;
    unsigned downsample, interleave;
    float depth_threshold;   // largest relative depth difference of continuous neighbours
    float normal_threshold;  // smallest cosine between the normals of continuous neighbours
};
LUCENT_RECORD(DiscontinuityRecord, gbuffer_position, gbuffer_normal, indirect, merged, downsample,
              interleave, depth_threshold, normal_threshold)

struct UpsampleRecord {
    lucent::BufferView<const float4> gbuffer_position, gbuffer_normal;
    lucent::BufferView<const float4> low;  // 1/downsample resolution
    lucent::BufferView<float4> full;
    unsigned downsample;
    float sigma;  // of the spatial Gaussian, in low-resolution pixels
};
LUCENT_RECORD(UpsampleRecord, gbuffer_position, gbuffer_normal, low, full, downsample, sigma)

struct ComposeRecord {
    lucent::BufferView<const float4> direct, gbuffer_albedo;
    lucent::BufferView<const float4> indirect;  // full resolution irradiance
    lucent::BufferView<float4> output;
};
LUCENT_RECORD(ComposeRecord, direct, gbuffer_albedo, indirect, output)

struct ParticleRecord {
    float3 Kd;
    lucent::TextureView diffuse_map;
};
LUCENT_RECORD(ParticleRecord, Kd, diffuse_map)

/// The crude geometry of imperfect visibility: each triangle's box, lo and hi, two float4
/// per triangle (made on the host), so a test reads one box rather than an index and three
/// vertices.
struct BoxRecord {
    lucent::BufferView<const float4> boxes;
};
LUCENT_RECORD(BoxRecord, boxes)

template <class Record>
LUCENT_HD inline IndirectParams indirect_params(const Record& rec) {
    return IndirectParams{rec.vpls,
                          rec.min_d,
                          rec.scene_size,
                          rec.top_object,
                          rec.imperfect_visibility,
                          rec.vpl_shadow_object,
                          rec.vpl_maps};
}

/// Nothing opaque between `from` and just short of `to`, both off their surfaces
/// (sample_common::offset_ray_origin: hit points, VPLs and area lights' emitters are): an
/// occlusion query, no programs.
LUCENT_HD inline bool visible(lucent::Handle root, unsigned ray_type, float3 from, float3 to,
                              lucent::Occlusion test = lucent::Occlusion::kExact) {
    return !lucent::occluded(root, sample_common::segment_ray(from, to, ray_type), test);
}

/// The imperfect_visibility option: how VPL shadow rays test the scene (IGI paper §4.1).
enum : unsigned {
    kExactVisibility = 0,  // the triangles
    kLeafBoxVisibility = 1,  // the boxes of the scene BVH's leaves (Occlusion::kLeafBoxes)
    kBoxGraphVisibility = 2,  // the paper's form: a second graph of one box per triangle
    kVisibilityMapVisibility = 3,  // a depth map per VPL (Ritschel et al. 2008), no shadow rays
};

// ---- visibility maps ---------------------------------------------------------------------
// The crude scene representation of the IGI paper's reference [3], imperfect shadow maps
// (Ritschel et al. 2008): each VPL keeps a small depth map of its hemisphere, and V(x, yk)
// is a lookup instead of a shadow ray. Ritschel et al. splat a point sample of the scene into
// each map; here each texel is one ray traced from the VPL (the kVplMapEntry pass), so a map
// is exact at its texels and only its resolution is imperfect. The hemisphere is stored as a
// paraboloid map (Heidrich and Seidel 1998; Brabec et al. 2002), the projection ISMs use too:
// a direction w with w.z >= 0 in the VPL's frame lands at (w.x, w.y) / (1 + w.z) in the unit
// disc, and the texel's angle is (1 + w.z) times its width in the disc.

/// An orthonormal frame around the unit normal n (Duff et al. 2017, "Building an
/// orthonormal basis, revisited"): continuous everywhere but at n.z = -0 vs +0.
struct VplFrame {
    float3 t, b, n;
};
LUCENT_HD inline VplFrame vpl_frame(float3 n) {
    const float sign = n.z >= 0.0f ? 1.0f : -1.0f;
    const float a = -1.0f / (sign + n.z), c = n.x * n.y * a;
    return VplFrame{make_float3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x),
                    make_float3(c, sign + n.y * n.y * a, -n.y), n};
}

/// The world direction of texel (i, j) of a size x size map around frame f. Texels outside
/// the unit disc (its corners; bilinear lookups at the rim read them) take the direction of
/// the rim: along the VPL's surface.
LUCENT_HD inline float3 vpl_map_direction(const VplFrame& f, unsigned i, unsigned j,
                                          unsigned size) {
    float u = 2.0f * (float(i) + 0.5f) / float(size) - 1.0f;
    float v = 2.0f * (float(j) + 0.5f) / float(size) - 1.0f;
    const float r2 = u * u + v * v;
    if (r2 > 1.0f) {
        const float inv = 1.0f / sqrtf(r2);
        u *= inv;
        v *= inv;
    }
    const float q = u * u + v * v, k = 1.0f / (1.0f + q);
    return f.t * (2.0f * u * k) + f.b * (2.0f * v * k) + f.n * ((1.0f - q) * k);
}

/// V(x, yk) from VPL k's map, in [0, 1]: the four texels nearest the direction from the VPL
/// to x, each 1 where its depth reaches x, weighted bilinearly (percentage-closer filtering,
/// Reeves et al. 1987). x is at distance d from the VPL and sees it at cosine cos_x. A texel
/// whose ray meets x's own surface a little nearer than x (its direction is up to a texel
/// off) must not shadow x: the tolerance is that texel's footprint on the surface, one and a
/// half texel angles times d times tan of x's angle, plus the thousandth of the way that the
/// shadow ray leaves out too (sample_common::kSegmentStart).
LUCENT_HD inline float map_visibility(const IndirectParams& p, unsigned k, const Vpl& vpl,
                                      float3 x, float d, float cos_x) {
    const unsigned size = p.vpl_maps.size.x;
    const VplFrame f = vpl_frame(vpl.normal);
    // The paraboloid coordinates of w = v / d are (v.t, v.b) / (d + v.n): one division.
    const float3 v = x - vpl.position;
    const float vz = lc_max(0.0f, dot(v, f.n)), s = 1.0f / (d + vz);
    const float fx = (dot(v, f.t) * s + 1.0f) * 0.5f * float(size) - 0.5f;
    const float fy = (dot(v, f.b) * s + 1.0f) * 0.5f * float(size) - 0.5f;
    const float x0 = floorf(fx), y0 = floorf(fy), ax = fx - x0, ay = fy - y0;
    // d times the texel's angle, 2 (1 + w.z) / size, is 2 (d + v.n) / size.
    const float tan_x = lc_min(8.0f, sqrtf(lc_max(0.0f, 1.0f - cos_x * cos_x)) / cos_x);
    const float reach = d * (1.0f - sample_common::kSegmentStart) -
                        1.5f * (2.0f * (d + vz) / float(size)) * tan_x;
    const int last = int(size) - 1;
    float visibility = 0.0f;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            const int tx = lc_min(last, lc_max(0, int(x0) + i));
            const int ty = lc_min(last, lc_max(0, int(y0) + j));
            const float weight = (i ? ax : 1.0f - ax) * (j ? ay : 1.0f - ay);
            if (p.vpl_maps[make_uint3(unsigned(tx), unsigned(ty), k)] >= reach)
                visibility += weight;
        }
    return visibility;
}

/// V(x, yk) of Eq. (1), in [0, 1]: against the scene, or, with imperfect visibility (IGI
/// paper §4.1), against boxes (the scene's own BVH leaf boxes, or the paper's second graph
/// of the triangles' bounding boxes: a different root and ray type) or from VPL k's
/// visibility map. x is at distance d from the VPL, at cosine cos_x.
LUCENT_HD inline float vpl_visibility(const IndirectParams& p, unsigned k, const Vpl& vpl,
                                      float3 x, float d, float cos_x) {
    if (p.imperfect_visibility == kVisibilityMapVisibility)
        return map_visibility(p, k, vpl, x, d, cos_x);
    bool seen;
    if (p.imperfect_visibility == kLeafBoxVisibility)
        seen = visible(p.top_object, kShadowRay, x, vpl.position, lucent::Occlusion::kLeafBoxes);
    else if (p.imperfect_visibility == kBoxGraphVisibility)
        seen = visible(p.vpl_shadow_object, kVplShadowRay, x, vpl.position);
    else
        seen = visible(p.top_object, kShadowRay, x, vpl.position);
    return seen ? 1.0f : 0.0f;
}

/// Eq. (1) at x with normal n over the VPLs first, first + stride, ...: the sum of
/// Le,k V(x, yk) G(x, yk), with G bounded by f(0.8 min_d, 1.2 min_d, |x - yk|). Incident
/// irradiance: rho / pi multiplies it at composition (IGI paper §4.2).
LUCENT_HD inline float3 indirect(const IndirectParams& p, float3 x, float3 n, unsigned first = 0,
                                 unsigned stride = 1) {
    float3 sum = make_float3(0.0f);
    for (unsigned k = first; k < p.vpls.count(); k += stride) {
        const Vpl vpl = p.vpls[k];
        if (max_component(vpl.radiance) <= 0.0f) continue;
        const float3 to = vpl.position - x;
        const float d2 = dot(to, to), d = sqrtf(d2);
        const float cos_x = dot(n, to) / d, cos_y = -dot(vpl.normal, to) / d;
        if (cos_x <= 0.0f || cos_y <= 0.0f) continue;
        const float g = cos_x * cos_y / d2 * smoothing(0.8f * p.min_d, 1.2f * p.min_d, d);
        if (g <= 0.0f) continue;
        const float v = vpl_visibility(p, k, vpl, x, d, cos_x);
        if (v > 0.0f) sum += vpl.radiance * (g * v);
    }
    return sum;
}

/// The full-resolution pixel whose G-buffer stands for low-resolution pixel q: the centre
/// of its N x N block, clamped to the image; the same layer.
LUCENT_HD inline uint3 representative_pixel(uint3 q, unsigned downsample, uint2 full_size) {
    return make_uint3(lc_min(q.x * downsample + downsample / 2, full_size.x - 1),
                      lc_min(q.y * downsample + downsample / 2, full_size.y - 1), q.z);
}

LUCENT_HD inline float3 xyz(float4 v) {
    return make_float3(v.x, v.y, v.z);
}

template <class T>
LUCENT_HD inline uint2 size2(const lucent::BufferView<T>& b) {
    return make_uint2(b.size.x, b.size.y);
}


// ---- VPL generation: one thread per light path --------------------------------------------
LUCENT_RAY_GENERATION(igi_generate_vpls, igi::GenerateRecord) {
    const unsigned path = lucent::launch_index().x, paths = lucent::launch_size().x;
    for (unsigned b = 0; b < rec.bounces; ++b) rec.vpls[path * rec.bounces + b] = igi::Vpl{};
    // The host shared the paths among the lights by flux (LightPath); each light walks its own
    // Halton sequence (index i), rotated per light (Cranley-Patterson) so that lights of one
    // area light do not share directions.
    const igi::LightPath start = rec.light_paths[path];
    const unsigned light_index = start.emitter;
    const igi::PointEmitter light = rec.lights[light_index];
    const unsigned i = start.sequence;
    const float r2 = igi::halton(light_index + 1, 5), r3 = igi::halton(light_index + 1, 7);
    const float u1 = igi::wrap01(igi::halton(i, 2) + r2), u2 = igi::wrap01(igi::halton(i, 3) + r3);
    float3 direction;
    if (igi::is_oriented(light)) {
        direction = igi::cosine_direction(light.normal, u1, u2);
    } else {  // uniform on the sphere
        const float z = 1.0f - 2.0f * u1, phi = 6.2831853f * u2;
        const float s = sqrtf(lc_max(0.0f, 1.0f - z * z));
        direction = make_float3(s * cosf(phi), s * sinf(phi), z);
    }
    float3 origin = light.position;
    float3 flux = start.flux;  // the light's flux shared by its paths
    (void)paths;
    const unsigned primes[] = {11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71};
    for (unsigned b = 0; b < rec.bounces; ++b) {
        igi::ParticlePayload hit{};
        lucent::trace(rec.top_object,
                      lucent::make_ray(origin, direction, igi::kParticleRay, 0.0f),
                      hit);
        if (!hit.hit || max_component(hit.albedo) <= 0.0f) break;  // a VPL only where diffuse
        const float3 n = faceforward(hit.normal, direction);
        // The VPL just off its surface, on the side the light came from: where the next
        // bounce starts, and an end of the shadow rays that test it.
        origin = sample_common::offset_ray_origin(hit.position, n, rec.scene_size);
        rec.vpls[path * rec.bounces + b] =
            igi::Vpl{origin, n, flux * hit.albedo * (1.0f / 3.14159265f)};
        flux = flux * hit.albedo;  // cosine sampling cancels the cosine and pi
        direction = igi::cosine_direction(n, igi::halton(i, primes[(2 * b) % 16]),
                                          igi::halton(i, primes[(2 * b + 1) % 16]));
    }
}

LUCENT_CLOSEST_HIT(igi_particle_hit, igi::ParticleRecord, igi::ParticlePayload,
                   igi::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    prd.hit = true;
    prd.position = ray.origin + lucent::t_hit() * ray.direction;
    prd.normal = normalize(lucent::object_to_world_normal(attr.geometric_normal));
    prd.albedo = rec.Kd * sample_common::diffuse_texel(rec.diffuse_map, attr.uv);
}

/// The radiance along one branch of the specular tree below a hit at `depth`, its hit's
/// indirect term inline (it hands no G-buffer layer back).
LUCENT_HD inline float3 inline_branch(const SurfaceRecord& rec, int depth, float3 from,
                                      float3 towards) {
    RadiancePayload child{};
    child.depth = depth + 1;
    child.separate = 0;
    child.surfel.distance = -1.0f;
    lucent::trace(rec.top_object, lucent::make_ray(from, towards, kRadianceRay, 0.0f), child);
    return child.color;
}

/// The radiance of a smooth dielectric's two branches of the specular tree at x (the
/// Whitted tree the paper's direct stage traces for mirrors, here for glass): reflection
/// weighted by the exact Fresnel reflectance F, refraction by 1 - F and by 1 / eta^2 (the
/// radiance's compression into the denser side, as the path tracer's glass:
/// pathtracer_bsdf.h); total internal reflection reflects all. Both branches get their
/// indirect term inline.
LUCENT_HD inline float3 dielectric(const SurfaceRecord& rec, int depth, float3 x, float3 direction,
                                   float3 geometric_normal) {
    const float3 d = normalize(direction);
    const float3 ng = normalize(lucent::object_to_world_normal(geometric_normal));
    const bool outside = dot(ng, d) < 0.0f;  // the winding's front is the outside
    const float3 n = outside ? ng : -ng;     // towards the incident side
    const float eta = outside ? rec.ior : 1.0f / rec.ior;  // n_transmitted / n_incident
    const float f = sample_common::fresnel_dielectric(-dot(d, n), eta);
    float3 color = make_float3(0.0f);
    if (f > 0.0f)
        color += f * inline_branch(rec, depth,
                                   sample_common::offset_ray_origin(x, n, rec.scene_size),
                                   reflect(d, n));
    float3 t;
    if (f < 1.0f && refract(t, d, n, 1.0f / eta))
        color += ((1.0f - f) / (eta * eta)) *
                 inline_branch(rec, depth, sample_common::offset_ray_origin(x, -n, rec.scene_size),
                               t);
    return color;
}

// ---- visibility maps: one depth ray per texel of each VPL's map -----------------------------
// Launched over size x size x VPLs after VPL generation, with imperfect_visibility=3.
LUCENT_RAY_GENERATION(igi_vpl_maps, igi::VplMapRecord) {
    const uint3 i = lucent::launch_index(), n = lucent::launch_size();
    const igi::Vpl vpl = rec.vpls[i.z];
    igi::DepthPayload depth{0.0f};  // an unused VPL's map is never read
    if (max_component(vpl.radiance) > 0.0f) {
        depth.distance = 3.0e38f;  // a miss: nothing in the way at any distance
        const float3 w = igi::vpl_map_direction(igi::vpl_frame(vpl.normal), i.x, i.y, n.x);
        lucent::trace(rec.top_object, lucent::make_ray(vpl.position, w, igi::kVplDepthRay, 0.0f),
                      depth);
    }
    rec.vpl_maps[i] = depth.distance;
}

// Every surface stops a depth ray, as every triangle blocks a shadow ray (occluded()).
LUCENT_CLOSEST_HIT(igi_depth_hit, lucent::NoRecord, igi::DepthPayload, igi::HitAttributes) {
    prd.distance = lucent::t_hit();
}

// ---- the direct stage: direct light, the specular tree, the G-buffer -----------------------
LUCENT_RAY_GENERATION(igi_camera, igi::CameraRecord) {
    const uint3 p = lucent::launch_index(), n = lucent::launch_size();
    const sample_common::PinholeCamera c = rec.camera[0u];
    igi::RadiancePayload prd{};
    prd.separate = 1;
    prd.surfel.distance = -1.0f;
    prd.reflected.distance = -1.0f;
    lucent::trace(rec.top_object,
                  lucent::make_ray(c.eye, sample_common::pixel_centre_direction(c, p, n),
                                   igi::kRadianceRay, 0.0f),
                  prd);
    rec.direct[make_uint2(p.x, p.y)] = make_float4(prd.color, 1.0f);
    const unsigned layers = rec.gbuffer_position.size.z;
    for (unsigned layer = 0; layer < layers; ++layer) {
        const igi::Surfel& s = layer == 0 ? prd.surfel : prd.reflected;
        const uint3 at = make_uint3(p.x, p.y, layer);
        rec.gbuffer_position[at] = make_float4(s.position, s.distance);
        rec.gbuffer_normal[at] = make_float4(s.normal, 0.0f);
        rec.gbuffer_albedo[at] = make_float4(s.albedo, 0.0f);
    }
}

LUCENT_CLOSEST_HIT(igi_surface, igi::SurfaceRecord, igi::RadiancePayload, igi::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    const float3 x = ray.origin + lucent::t_hit() * ray.direction;
    const float3 n = faceforward(normalize(lucent::object_to_world_normal(attr.geometric_normal)),
                                 ray.direction);
    const float3 origin = sample_common::offset_ray_origin(x, n, rec.scene_size);
    float3 color = rec.Ke;
    const float3 rho = rec.Kd * sample_common::diffuse_texel(rec.diffuse_map, attr.uv);
    const float3 albedo = rho * (1.0f / 3.14159265f);
    if (max_component(rho) > 0.0f) {
        for (unsigned l = 0; l < rec.lights.count(); ++l) {
            const igi::PointEmitter light = rec.lights[l];
            const float3 to = light.position - x;
            const float d2 = dot(to, to), d = sqrtf(d2), c = dot(n, to) / d;
            if (c <= 0.0f) continue;
            const float3 intensity = igi::intensity_towards(light, -to / d);
            if (max_component(intensity) > 0.0f &&
                igi::visible(rec.top_object, igi::kShadowRay, origin, light.position))
                color += albedo * intensity * (c / d2);
        }
    }
    // The primary hit's indirect term is a stage of its own, and so is the first reflected
    // hit's with the reflection layer: those hits hand their G-buffer layer back, whose
    // albedo is the textured rho, so that composition applies the texture at full resolution
    // (IGI paper §4.2). Other hits get it here.
    if (prd.separate)
        prd.surfel = igi::Surfel{origin, n, rho, lucent::t_hit()};
    else if (max_component(rho) > 0.0f)
        color += albedo * igi::indirect(igi::indirect_params(rec), origin, n);
    if (rec.ior > 0.0f && prd.depth + 1 < int(rec.max_depth))
        color += igi::dielectric(rec, prd.depth, x, ray.direction, attr.geometric_normal);
    if (max_component(rec.Ks) > 0.0f && prd.depth + 1 < int(rec.max_depth)) {
        igi::RadiancePayload reflected{};
        reflected.depth = prd.depth + 1;
        reflected.separate = prd.depth == 0 && rec.reflection_layer != 0u ? 1u : 0u;
        reflected.surfel.distance = -1.0f;
        lucent::trace(
            rec.top_object,
            lucent::make_ray(origin, reflect(normalize(ray.direction), n), igi::kRadianceRay, 0.0f),
            reflected);
        color += rec.Ks * reflected.color;
        if (prd.depth == 0 && reflected.surfel.distance >= 0.0f) {
            // Layer 1: the reflected hit, its irradiance seen through the mirror's Ks, at its
            // distance along the eye path (what the discontinuity buffer compares).
            prd.reflected = reflected.surfel;
            prd.reflected.albedo = rec.Ks * reflected.surfel.albedo;
            prd.reflected.distance += lucent::t_hit();
        }
    }
    prd.color = color;
}

LUCENT_MISS(igi_miss, lucent::NoRecord, igi::RadiancePayload) {
    prd.color = make_float3(0.0f);
}

// ---- the indirect stage: Eq. (1) at the primary hits (IGI paper §4.2, §4.3) --------------------
LUCENT_RAY_GENERATION(igi_indirect, igi::IndirectRecord) {
    const uint3 q = lucent::launch_index();
    const unsigned layer = q.z / rec.slices, slice = q.z % rec.slices;
    const uint3 full = igi::representative_pixel(make_uint3(q.x, q.y, layer), rec.downsample,
                                                 igi::size2(rec.gbuffer_position));
    const float4 position = rec.gbuffer_position[full];
    if (position.w < 0.0f) {
        rec.indirect[q] = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
        return;
    }
    // Interleaved sampling: pixel (x, y) of each M x M tile takes VPL subset x + M y, every
    // M^2-th VPL; M^2 times its sum estimates the whole set's. Slice s of S takes every S-th
    // VPL of the subset, from its s-th.
    const unsigned m = rec.interleave, subset = (q.x % m) + m * (q.y % m);
    const float3 e =
        igi::indirect(igi::indirect_params(rec), igi::xyz(position),
                      igi::xyz(rec.gbuffer_normal[full]), subset + m * m * slice,
                      m * m * rec.slices);
    rec.indirect[q] = make_float4(e * float(m * m), 1.0f);
}

// The slices of a pixel's VPLs, added up: the indirect irradiance of each layer.
LUCENT_RAY_GENERATION(igi_indirect_sum, igi::IndirectSumRecord) {
    const uint3 q = lucent::launch_index();
    float4 sum = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
    for (unsigned s = 0; s < rec.slices; ++s) {
        const float4 part = rec.indirect_slices[make_uint3(q.x, q.y, q.z * rec.slices + s)];
        sum = make_float4(sum.x + part.x, sum.y + part.y, sum.z + part.z, part.w);
    }
    rec.indirect[q] = sum;
}

// The discontinuity buffer (IGI paper §4.3): a pixel averages the irradiance of the neighbours of
// its M x M window whose depth and normal say the surface is continuous.
LUCENT_RAY_GENERATION(igi_discontinuity, igi::DiscontinuityRecord) {
    const uint3 q = lucent::launch_index(), size = lucent::launch_size();
    const uint2 full_size = igi::size2(rec.gbuffer_position);
    const uint3 centre = q;
    const uint3 c_full = igi::representative_pixel(centre, rec.downsample, full_size);
    const float4 c_position = rec.gbuffer_position[c_full];
    if (c_position.w < 0.0f) {
        rec.merged[centre] = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
        return;
    }
    const float3 c_normal = igi::xyz(rec.gbuffer_normal[c_full]);
    const int radius = int(rec.interleave / 2);
    float3 sum = make_float3(0.0f);
    float count = 0.0f;
    for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= radius; ++dx) {
            const int x = int(q.x) + dx, y = int(q.y) + dy;
            if (x < 0 || y < 0 || x >= int(size.x) || y >= int(size.y)) continue;
            const uint3 nb = make_uint3(unsigned(x), unsigned(y), q.z);
            const uint3 nb_full = igi::representative_pixel(nb, rec.downsample, full_size);
            const float4 position = rec.gbuffer_position[nb_full];
            const bool is_centre = dx == 0 && dy == 0;  // always counts, whatever the thresholds
            if (!is_centre) {
                if (position.w < 0.0f) continue;
                if (fabsf(position.w - c_position.w) > rec.depth_threshold * c_position.w) continue;
                if (dot(igi::xyz(rec.gbuffer_normal[nb_full]), c_normal) < rec.normal_threshold)
                    continue;
            }
            sum += igi::xyz(rec.indirect[nb]);
            count += 1.0f;
        }
    rec.merged[centre] = make_float4(sum / count, 1.0f);  // count >= 1: the centre itself
}

// Joint bilateral upsampling, Eq. (2) (IGI paper §4.2, after Kopf et al. 2007): a Gaussian over the
// low-resolution neighbours q of p, times the cosine between the full-resolution normals at p~
// and at q~, normalised.
LUCENT_RAY_GENERATION(igi_upsample, igi::UpsampleRecord) {
    const uint3 p = lucent::launch_index(), full = p;
    const uint2 full_size = igi::size2(rec.gbuffer_position);
    const uint2 low_size = igi::size2(rec.low);
    if (rec.gbuffer_position[full].w < 0.0f) {
        rec.full[full] = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
        return;
    }
    const float3 n = igi::xyz(rec.gbuffer_normal[full]);
    // p in low-resolution pixel coordinates (pixel centres at integers).
    const float n_down = float(rec.downsample);
    const float cx = (float(p.x) + 0.5f) / n_down - 0.5f, cy = (float(p.y) + 0.5f) / n_down - 0.5f;
    const int x0 = int(floorf(cx)), y0 = int(floorf(cy));
    const float inv_two_sigma2 = 1.0f / (2.0f * rec.sigma * rec.sigma);
    float3 sum = make_float3(0.0f), nearest = make_float3(0.0f);
    float k = 0.0f, nearest_d2 = 1e30f;
    for (int y = y0 - 1; y <= y0 + 2; ++y)
        for (int x = x0 - 1; x <= x0 + 2; ++x) {
            if (x < 0 || y < 0 || x >= int(low_size.x) || y >= int(low_size.y)) continue;
            const uint3 q = make_uint3(unsigned(x), unsigned(y), p.z);
            const uint3 q_full = igi::representative_pixel(q, rec.downsample, full_size);
            if (rec.gbuffer_position[q_full].w < 0.0f) continue;  // background: no irradiance
            const float d2 = (float(x) - cx) * (float(x) - cx) + (float(y) - cy) * (float(y) - cy);
            const float3 value = igi::xyz(rec.low[q]);
            if (d2 < nearest_d2) {
                nearest_d2 = d2;
                nearest = value;
            }
            const float w = expf(-d2 * inv_two_sigma2) *
                            lc_max(0.0f, dot(n, igi::xyz(rec.gbuffer_normal[q_full])));
            sum += value * w;
            k += w;
        }
    // No neighbour faces p's way (a thin feature between low-resolution samples): the
    // nearest sample is the best guess left.
    rec.full[full] = make_float4(k > 0.0f ? sum / k : nearest, 1.0f);
}

// Composition (IGI paper, Fig. 3): the direct image plus, for each G-buffer layer, its weight (rho,
// or Ks rho through a mirror) / pi times its indirect irradiance.
LUCENT_RAY_GENERATION(igi_compose, igi::ComposeRecord) {
    const uint3 p = lucent::launch_index();
    float3 color = igi::xyz(rec.direct[make_uint2(p.x, p.y)]);
    for (unsigned layer = 0; layer < rec.gbuffer_albedo.size.z; ++layer) {
        const uint3 at = make_uint3(p.x, p.y, layer);
        color += igi::xyz(rec.gbuffer_albedo[at]) * (1.0f / 3.14159265f) *
                 igi::xyz(rec.indirect[at]);
    }
    rec.output[make_uint2(p.x, p.y)] = make_float4(color, 1.0f);
}

// ---- the crude scene of imperfect visibility: one box per triangle -------------------------
LUCENT_BOUNDING_BOX(igi_triangle_box_bounds, igi::BoxRecord) {
    box.lo = igi::xyz(rec.boxes[2 * prim]);
    box.hi = igi::xyz(rec.boxes[2 * prim + 1]);
}

LUCENT_INTERSECTION(igi_triangle_box_intersect, igi::BoxRecord, igi::HitAttributes) {
    const float4 lo4 = rec.boxes[2 * prim], hi4 = rec.boxes[2 * prim + 1];
    const lucent::Ray& ray = lucent::current_ray();
    // Slab test over the whole line; a flat box (an axis-aligned triangle) still stops rays
    // that cross its plane. A box that holds either end of the segment does not stop it: a
    // tilted triangle's box holds the triangle and its neighbours, which would otherwise
    // shadow themselves from every VPL. Only boxes wholly between the ends occlude.
    float t0 = -1e30f, t1 = 1e30f;
    const float o[3] = {ray.origin.x, ray.origin.y, ray.origin.z};
    const float d[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
    const float l[3] = {lo4.x, lo4.y, lo4.z}, h[3] = {hi4.x, hi4.y, hi4.z};
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
    if (t0 <= ray.tmin || t1 >= ray.tmax) return;
    // Occlusion queries (the only rays traced here) run no hit program: no attributes.
    if (lucent::potential_intersection(t0)) lucent::report_intersection(0);
}

}  // namespace igi

// Programs of the Whitted sample (OptiX paper §6.1, Fig. 7): a re-creation of Whitted's
// sphere scene (Whitted 1980) after the OptiX SDK's "whitted" sample. One pinhole camera
// with optional adaptive supersampling, three primitive types with their own intersection
// and bounding-box programs (parallelogram floor, sphere, thin-shell glass sphere), a
// checkered Phong floor, a reflective metal, a Fresnel glass, point lights with shadow rays
// whose any-hit programs either stop the ray (opaque) or attenuate it (glass).
//
// Secondary rays (shadow, reflection, refraction) start at the hit point moved off the surface
// by Wächter and Binder's offset (Ray Tracing Gems, ch. 6; samples/common/ray_offset.h), which
// follows the float spacing at the hit and the scene's size, and are traced from tmin 0: the
// scene renders alike at any scale and far from the origin (tests/scale_test.cpp).
//
// Single source: compiled by g++ into the host (CPU backend) and by NVRTC for the GPU, so
// it uses only lucent/device.h, the C math functions and the samples' shared pinhole camera
// and ray offset (samples/common/).
//
// Everything lives in namespace `whitted`, the namespace of its module: the host names a
// program as LUCENT_PROGRAM(whitted::whitted_camera).
#pragma once

#include "lucent/device.h"
#include "samples/common/camera.h"
#include "samples/common/ray_offset.h"

namespace whitted {

/// The module of this sample's programs (lucent/device/module.h).
LUCENT_MODULE(whitted)

using lucent::BufferView;
using lucent::Handle;
using lucent::TextureView;

constexpr unsigned kRadianceRay = 0;
constexpr unsigned kShadowRay = 1;

/// A point light; lights with casts_shadow == 0 light through everything.
struct BasicLight {
    float3 position;
    float3 color;
    int casts_shadow;
    int padding;
};

/// Payload of radiance rays: the colour returned up the ray tree, the weight of this ray
/// in the final pixel (to cut off rays that cannot matter) and its depth in the tree.
struct RadiancePayload {
    float3 result;
    float importance;
    int depth;
};

/// Payload of shadow rays: the fraction of the light's colour that gets through.
struct ShadowPayload {
    float3 attenuation;
};

/// hit_kind bits written by the intersection programs.
enum HitKind : unsigned {
    kHitBackFace = 1u,  // the ray leaves the solid (travels along the outward normal)
    kHitInner = 2u,     // the inner surface of the glass shell
};

/// Attributes of every primitive of the scene. The normals point out of the solid (for the
/// glass shell: out of the glass, i.e. towards the centre on the inner surface).
struct HitAttributes {
    float3 geometric_normal;
    float3 shading_normal;
    float2 texcoord;
    unsigned hit_kind;
};

// ---- records (the programs' variables) ---------------------------------------

struct CameraRecord {
    BufferView<sample_common::PinholeCamera> camera;  // one element: W to the image centre
    BufferView<float4> output_buffer;
    Handle top_object;
    int antialiasing;    // 0: one ray per pixel; 1: adaptive 4 → 16 samples
    float aa_threshold;  // colour difference (max channel) that triggers supersampling
    int motion;          // 1: each camera ray samples a time in the shutter [0, 1]
};
LUCENT_RECORD(CameraRecord, camera, output_buffer, top_object, antialiasing, aa_threshold, motion)

struct ExceptionRecord {
    BufferView<float4> output_buffer;
    float3 bad_color;
};
LUCENT_RECORD(ExceptionRecord, output_buffer, bad_color)

struct MissRecord {
    float3 bg_color;
};
LUCENT_RECORD(MissRecord, bg_color)

struct SphereRecord {
    float4 sphere;  // centre xyz, radius w
};
LUCENT_RECORD(SphereRecord, sphere)

struct ShellRecord {
    float3 center;
    float radius_outer;
    float radius_inner;
};
LUCENT_RECORD(ShellRecord, center, radius_outer, radius_inner)

struct ParallelogramRecord {
    float4 plane;   // unit normal xyz, offset w (dot(normal, p) == w on the plane)
    float3 v1, v2;  // edges scaled by 1 / |edge|^2, so dot(v, p - anchor) is in [0, 1]
    float3 anchor;
};
LUCENT_RECORD(ParallelogramRecord, plane, v1, v2, anchor)

struct PhongRecord {
    float3 Ka, Kd, Ks;
    float phong_exp;
    float3 reflectivity;
    // Context scope:
    float3 ambient_light_color;
    BufferView<BasicLight> lights;
    Handle top_object, top_shadower;
    float scene_size;  // the scene's longest side: ray offsets follow it
    int max_depth;
    int shadows;  // 0: shadow rays off (every light reaches every point that faces it)
};
LUCENT_RECORD(PhongRecord, Ka, Kd, Ks, phong_exp, reflectivity, ambient_light_color, lights,
              top_object, top_shadower, scene_size, max_depth, shadows)

struct CheckerRecord {
    TextureView checker;   // float4 texels: rgb is the colour (ambient = diffuse)
    float2 checker_scale;  // texture repeats across the parallelogram's (u, v)
    float3 Ks;
    float phong_exp;
    float3 reflectivity;
    float3 ambient_light_color;
    BufferView<BasicLight> lights;
    Handle top_object, top_shadower;
    float scene_size;
    int max_depth;
    int shadows;
};
LUCENT_RECORD(CheckerRecord, checker, checker_scale, Ks, phong_exp, reflectivity,
              ambient_light_color, lights, top_object, top_shadower, scene_size, max_depth,
              shadows)

struct GlassRecord {
    float fresnel_exponent, fresnel_minimum, fresnel_maximum;
    float refraction_index;
    float3 refraction_color, reflection_color;
    float3 extinction_constant;  // log of the transmittance per unit distance (Beer's law)
    float3 cutoff_color;         // stands in for rays too unimportant to trace
    float importance_cutoff;
    int refraction_maxdepth, reflection_maxdepth;
    int max_depth;
    float scene_size;
    Handle top_object;
};
LUCENT_RECORD(GlassRecord, fresnel_exponent, fresnel_minimum, fresnel_maximum, refraction_index,
              refraction_color, reflection_color, extinction_constant, cutoff_color,
              importance_cutoff, refraction_maxdepth, reflection_maxdepth, max_depth, scene_size,
              top_object)

struct GlassShadowRecord {
    float3 shadow_attenuation;  // transmission of one glass surface at normal incidence
};
LUCENT_RECORD(GlassShadowRecord, shadow_attenuation)

// ---- helpers -------------------------------------------------------------------

/// NTSC luminance, the SDK's weight of a colour in the importance of a ray.
LUCENT_HD inline float luminance(float3 c) {
    return dot(c, make_float3(0.30f, 0.59f, 0.11f));
}

/// Component-wise expf.
LUCENT_HD inline float3 expf3(float3 v) {
    return make_float3(expf(v.x), expf(v.y), expf(v.z));
}

/// Schlick's approximation of Fresnel reflectance with the SDK's free exponent and range:
/// exponent 5, minimum R0 and maximum 1 give Schlick's R0 + (1 - R0)(1 - cos)^5.
LUCENT_HD inline float fresnel_schlick(float cos_theta, float exponent, float minimum,
                                       float maximum) {
    return clampf(minimum + (maximum - minimum) * powf(lc_max(0.0f, 1.0f - cos_theta), exponent),
                  minimum, maximum);
}
LUCENT_HD inline float3 fresnel_schlick(float cos_theta, float exponent, float3 minimum,
                                        float3 maximum) {
    return make_float3(fresnel_schlick(cos_theta, exponent, minimum.x, maximum.x),
                       fresnel_schlick(cos_theta, exponent, minimum.y, maximum.y),
                       fresnel_schlick(cos_theta, exponent, minimum.z, maximum.z));
}

/// Roots t0 <= t1 of |o + t d - c| = r for a unit direction d, or false when the line misses.
/// Ray Tracing Gems ch. 7: the discriminant from the perpendicular distance and the near root
/// from c/q avoid the cancellation of the textbook formula far from the sphere.
LUCENT_HD inline bool sphere_roots(float3 o, float3 d, float3 center, float radius, float& t0,
                                   float& t1) {
    float3 f = o - center;
    float b = -dot(f, d);
    float3 perpendicular = f + b * d;
    float disc = radius * radius - dot(perpendicular, perpendicular);
    if (disc < 0.0f) return false;
    float c = dot(f, f) - radius * radius;
    float q = b + (b >= 0.0f ? sqrtf(disc) : -sqrtf(disc));
    if (q == 0.0f) {  // the line grazes the sphere exactly at o: a double root at 0
        t0 = t1 = 0.0f;
        return true;
    }
    float a = c / q;
    t0 = lc_min(a, q);
    t1 = lc_max(a, q);
    return true;
}

/// Ambient + Phong direct lighting with shadow rays from every light, plus a mirror
/// reflection ray weighted by `reflectivity` (the SDK's phongShade). `normal` faces the
/// incoming ray: both kinds of ray leave on its side.
template <class Rec>
LUCENT_HD inline void phong_shade(const Rec& rec, RadiancePayload& prd, float3 Ka, float3 Kd,
                                  float3 Ks, float phong_exp, float3 reflectivity, float3 normal) {
    const lucent::Ray& ray = lucent::current_ray();
    float3 hit_point = ray.origin + lucent::t_hit() * ray.direction;
    float3 dir = normalize(ray.direction);
    // The secondary rays' origin is computed where each is traced, not kept beside the hit
    // point across the light loop: kept live there, it made the megakernel 3.5 % slower
    // (1024x1024 on an H200: 0.904-0.911 ms a frame against 0.875-0.878 ms before the offset;
    // computed at each trace, 0.881-0.887 ms).

    float3 result = Ka * rec.ambient_light_color;
    for (unsigned i = 0; i < rec.lights.count(); ++i) {
        BasicLight light = rec.lights[i];
        float3 to_light = light.position - hit_point;
        float light_distance = length(to_light);
        float3 L = to_light / light_distance;
        float n_dot_l = dot(normal, L);
        if (n_dot_l <= 0.0f) continue;

        float3 light_attenuation = make_float3(1.0f);
        if (rec.shadows && light.casts_shadow) {
            ShadowPayload shadow_prd;
            shadow_prd.attenuation = make_float3(1.0f);
            // To the point light itself: no surface there to stop short of.
            const float3 origin =
                sample_common::offset_along_normal(hit_point, normal, rec.scene_size);
            lucent::trace(
                rec.top_shadower,
                lucent::make_ray(origin, L, kShadowRay, 0.0f, light_distance, lucent::ray_time()),
                shadow_prd);
            light_attenuation = shadow_prd.attenuation;
        }
        if (max_component(light_attenuation) <= 0.0f) continue;

        float3 light_color = light.color * light_attenuation;
        result += Kd * n_dot_l * light_color;
        float3 H = normalize(L - dir);
        float n_dot_h = dot(normal, H);
        if (n_dot_h > 0.0f) result += Ks * powf(n_dot_h, phong_exp) * light_color;
    }

    if (max_component(reflectivity) > 0.0f) {
        // Importance shrinks down the ray tree; a ray that can change the pixel by less
        // than 1 % is not traced (the SDK's cutoff).
        RadiancePayload reflected;
        reflected.importance = prd.importance * luminance(reflectivity);
        reflected.depth = prd.depth + 1;
        reflected.result = make_float3(0.0f);
        if (reflected.importance >= 0.01f && reflected.depth <= rec.max_depth) {
            float3 R = reflect(dir, normal);
            const float3 origin =
                sample_common::offset_along_normal(hit_point, normal, rec.scene_size);
            lucent::trace(rec.top_object,
                          lucent::make_ray(origin, R, kRadianceRay, 0.0f, lucent::kInfinity,
                                           lucent::ray_time()),
                          reflected);
            result += reflectivity * reflected.result;
        }
    }
    prd.result = result;
}

/// World-space unit normal of the hit, facing the incoming ray.
LUCENT_HD inline float3 facing_world_normal(const HitAttributes& attr) {
    float3 n = normalize(lucent::object_to_world_normal(attr.shading_normal));
    return faceforward(n, lucent::current_ray().direction);
}

/// Colour seen along the camera ray through image-plane point (sx, sy) in [-1, 1]^2.
/// At `time` (the secondary rays inherit it: the whole ray tree sees one instant).
LUCENT_HD inline float3 camera_sample(const CameraRecord& rec,
                                      const sample_common::PinholeCamera& c, float sx, float sy,
                                      float time) {
    float3 direction = normalize(sx * c.U + sy * c.V + c.W);
    RadiancePayload prd;
    prd.result = make_float3(0.0f);
    prd.importance = 1.0f;
    prd.depth = 0;
    lucent::trace(rec.top_object,
                  lucent::make_ray(c.eye, direction, kRadianceRay, 0.0f, lucent::kInfinity, time),
                  prd);
    return prd.result;
}

// ---- camera ----------------------------------------------------------------------

/// Pinhole camera (paper §6.1). With antialiasing on, four rays on a rotated grid decide
/// whether the pixel is smooth; if any differs from their mean by more than aa_threshold, the
/// other twelve cells of a 4x4 grid are traced too and all sixteen averaged (adaptive
/// supersampling: only edges, shadow borders and checker borders pay for it).
LUCENT_HD inline void render_pixel(const CameraRecord& rec) {
    const sample_common::PinholeCamera camera = rec.camera[0u];
    uint3 index = lucent::launch_index();
    uint3 size = lucent::launch_size();
    float inv_w = 1.0f / float(size.x), inv_h = 1.0f / float(size.y);
    // With motion, the one sample of a pixel is at time u in the shutter [0, 1], u from the
    // pixel's TEA hash; with antialiasing, sample i is at (k_i + u) / 16, k_i the bit-reversed
    // i, so the first four samples spread over the shutter as the sixteen do (stratified).
    // 16 rounds: TEA with 4 (Zafar et al.'s cheapest) left horizontal streaks in the time.
    const float pixel_time =
        rec.motion ? lucent::tea_unit_float(
                         lucent::tea<16>(make_uint2(index.x, index.y), lucent::zafar_tea_key()).x)
                   : 0.0f;
    // Pixel-relative (fx, fy) in [0, 1]^2 → image plane, y up (row 0 at the top).
    auto sample = [&](float fx, float fy, unsigned i) {
        float sx = 2.0f * (float(index.x) + fx) * inv_w - 1.0f;
        float sy = 1.0f - 2.0f * (float(index.y) + fy) * inv_h;
        const unsigned k = ((i & 1u) << 3) | ((i & 2u) << 1) | ((i & 4u) >> 1) | ((i & 8u) >> 3);
        const float time = !rec.motion        ? 0.0f
                           : rec.antialiasing ? (float(k) + pixel_time) * (1.0f / 16.0f)
                                              : pixel_time;
        return whitted::camera_sample(rec, camera, sx, sy, time);
    };

    float3 color;
    if (!rec.antialiasing) {
        color = sample(0.5f, 0.5f, 0u);
    } else {
        // Cells (column, row) of the 4x4 grid; the first four form the rotated grid.
        const int kCells[16][2] = {{1, 0}, {3, 1}, {0, 2}, {2, 3}, {0, 0}, {2, 0}, {3, 0}, {0, 1},
                                   {1, 1}, {2, 1}, {1, 2}, {2, 2}, {3, 2}, {0, 3}, {1, 3}, {3, 3}};
        float3 samples[4];
        for (int i = 0; i < 4; ++i)
            samples[i] = sample((float(kCells[i][0]) + 0.5f) * 0.25f,
                                (float(kCells[i][1]) + 0.5f) * 0.25f, unsigned(i));
        // Summed in pairs: four equal samples then average to exactly their value.
        float3 sum = (samples[0] + samples[1]) + (samples[2] + samples[3]);
        float3 mean = sum * 0.25f;
        float difference = 0.0f;
        for (int i = 0; i < 4; ++i) {
            float3 d = samples[i] - mean;
            difference = lc_max(difference, lc_max(fabsf(d.x), lc_max(fabsf(d.y), fabsf(d.z))));
        }
        if (difference > rec.aa_threshold) {
            for (int i = 4; i < 16; ++i)
                sum += sample((float(kCells[i][0]) + 0.5f) * 0.25f,
                              (float(kCells[i][1]) + 0.5f) * 0.25f, unsigned(i));
            color = sum * (1.0f / 16.0f);
        } else {
            color = mean;
        }
    }
    rec.output_buffer[make_uint2(index.x, index.y)] = make_float4(color, 1.0f);
}

LUCENT_RAY_GENERATION(whitted_camera, whitted::CameraRecord) {
    whitted::render_pixel(rec);
}

/// Marks a pixel whose launch raised an exception with an unmistakable colour.
LUCENT_EXCEPTION(whitted_exception, whitted::ExceptionRecord) {
    uint2 pixel = make_uint2(ex.launch_index.x, ex.launch_index.y);
    if (pixel.x < rec.output_buffer.size.x && pixel.y < rec.output_buffer.size.y)
        rec.output_buffer[pixel] = make_float4(rec.bad_color, 1.0f);
}

/// Constant background colour.
LUCENT_MISS(whitted_miss, whitted::MissRecord, whitted::RadiancePayload) {
    prd.result = rec.bg_color;
}

// ---- geometry --------------------------------------------------------------------

/// Solid sphere: both roots, nearest first, so a ray starting inside still hits.
LUCENT_INTERSECTION(whitted_sphere_intersect, whitted::SphereRecord, whitted::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    float3 center = make_float3(rec.sphere.x, rec.sphere.y, rec.sphere.z);
    float radius = rec.sphere.w;
    float inv_len = 1.0f / length(ray.direction);
    float3 d = ray.direction * inv_len;
    float t0, t1;
    if (!whitted::sphere_roots(ray.origin, d, center, radius, t0, t1)) return;
    float roots[2] = {t0 * inv_len, t1 * inv_len};
    for (int i = 0; i < 2; ++i) {
        if (!lucent::potential_intersection(roots[i])) continue;
        float3 n = (ray.origin + roots[i] * ray.direction - center) / radius;
        attr.geometric_normal = n;
        attr.shading_normal = n;
        attr.texcoord = make_float2(0.0f, 0.0f);
        attr.hit_kind = i == 0 ? 0u : unsigned(whitted::kHitBackFace);
        if (lucent::report_intersection(0)) return;
    }
}

LUCENT_BOUNDING_BOX(whitted_sphere_bounds, whitted::SphereRecord) {
    float3 center = make_float3(rec.sphere.x, rec.sphere.y, rec.sphere.z);
    float3 r = make_float3(rec.sphere.w);
    box.lo = center - r;
    box.hi = center + r;
}

/// Thin-shell sphere (paper §6.1: one specialised primitive instead of two spheres). Reports
/// the up to four crossings in order: outer in, inner in, inner out, outer out. The normal
/// always points out of the glass, so the material sees a plain glass/air interface.
LUCENT_INTERSECTION(whitted_shell_intersect, whitted::ShellRecord, whitted::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    float inv_len = 1.0f / length(ray.direction);
    float3 d = ray.direction * inv_len;
    float outer0, outer1;
    if (!whitted::sphere_roots(ray.origin, d, rec.center, rec.radius_outer, outer0, outer1)) return;
    float inner0 = 0.0f, inner1 = 0.0f;
    bool hits_inner =
        whitted::sphere_roots(ray.origin, d, rec.center, rec.radius_inner, inner0, inner1);

    float roots[4];
    unsigned kinds[4];
    int count = 0;
    roots[count] = outer0;
    kinds[count++] = 0u;
    if (hits_inner) {
        roots[count] = inner0;
        kinds[count++] = whitted::kHitInner | whitted::kHitBackFace;
        roots[count] = inner1;
        kinds[count++] = whitted::kHitInner;
    }
    roots[count] = outer1;
    kinds[count++] = whitted::kHitBackFace;

    for (int i = 0; i < count; ++i) {
        float t = roots[i] * inv_len;
        if (!lucent::potential_intersection(t)) continue;
        bool inner = (kinds[i] & whitted::kHitInner) != 0;
        float3 radial = (ray.origin + t * ray.direction - rec.center) /
                        (inner ? rec.radius_inner : rec.radius_outer);
        float3 n = inner ? -radial : radial;  // out of the glass
        attr.geometric_normal = n;
        attr.shading_normal = n;
        attr.texcoord = make_float2(0.0f, 0.0f);
        attr.hit_kind = kinds[i];
        if (lucent::report_intersection(0)) return;
    }
}

LUCENT_BOUNDING_BOX(whitted_shell_bounds, whitted::ShellRecord) {
    float3 r = make_float3(rec.radius_outer);
    box.lo = rec.center - r;
    box.hi = rec.center + r;
}

/// Parallelogram anchor + a v1 + b v2, (a, b) in [0, 1]^2, with (a, b) as texture coordinate.
LUCENT_INTERSECTION(whitted_parallelogram_intersect, whitted::ParallelogramRecord,
                    whitted::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    float3 n = make_float3(rec.plane.x, rec.plane.y, rec.plane.z);
    float d_dot_n = dot(ray.direction, n);
    if (d_dot_n == 0.0f) return;
    float t = (rec.plane.w - dot(n, ray.origin)) / d_dot_n;
    float3 offset = ray.origin + t * ray.direction - rec.anchor;
    float a = dot(rec.v1, offset);
    if (a < 0.0f || a > 1.0f) return;
    float b = dot(rec.v2, offset);
    if (b < 0.0f || b > 1.0f) return;
    if (!lucent::potential_intersection(t)) return;
    attr.geometric_normal = n;
    attr.shading_normal = n;
    attr.texcoord = make_float2(a, b);
    attr.hit_kind = d_dot_n > 0.0f ? unsigned(whitted::kHitBackFace) : 0u;
    lucent::report_intersection(0);
}

LUCENT_BOUNDING_BOX(whitted_parallelogram_bounds, whitted::ParallelogramRecord) {
    // v1 and v2 are stored scaled by 1/|v|^2; scale back for the corners.
    float3 e1 = rec.v1 / dot(rec.v1, rec.v1);
    float3 e2 = rec.v2 / dot(rec.v2, rec.v2);
    float3 p00 = rec.anchor, p10 = rec.anchor + e1, p01 = rec.anchor + e2;
    float3 p11 = rec.anchor + e1 + e2;
    // A flat box is valid but leaves no margin for the slab test's rounding: pad it, by a
    // share of its size and, far from the origin, by a few float spacings of its corner
    // (there a share of the size alone can round away).
    float3 far = fmaxf(fmaxf(fmaxf(p00, -p00), fmaxf(p10, -p10)),
                       fmaxf(fmaxf(p01, -p01), fmaxf(p11, -p11)));
    float3 pad = make_float3(1e-4f * (length(e1) + length(e2)) + 1e-6f * max_component(far));
    box.lo = fminf(fminf(p00, p10), fminf(p01, p11)) - pad;
    box.hi = fmaxf(fmaxf(p00, p10), fmaxf(p01, p11)) + pad;
}

// ---- materials -----------------------------------------------------------------

/// Reflective Phong metal.
LUCENT_CLOSEST_HIT(whitted_metal_radiance, whitted::PhongRecord, whitted::RadiancePayload,
                   whitted::HitAttributes) {
    whitted::phong_shade(rec, prd, rec.Ka, rec.Kd, rec.Ks, rec.phong_exp, rec.reflectivity,
                         whitted::facing_world_normal(attr));
}

/// Phong floor whose ambient and diffuse colour come from a checker texture.
LUCENT_CLOSEST_HIT(whitted_checker_radiance, whitted::CheckerRecord, whitted::RadiancePayload,
                   whitted::HitAttributes) {
    float2 uv =
        make_float2(attr.texcoord.x * rec.checker_scale.x, attr.texcoord.y * rec.checker_scale.y);
    float3 color = make_float3(lucent::tex2D(rec.checker, uv));
    whitted::phong_shade(rec, prd, color, color, rec.Ks, rec.phong_exp, rec.reflectivity,
                         whitted::facing_world_normal(attr));
}

/// Glass: Schlick-Fresnel split into a refracted and a reflected ray, each traced while it
/// still matters (importance) and the tree is shallow enough; Beer's law inside the glass.
LUCENT_CLOSEST_HIT(whitted_glass_radiance, whitted::GlassRecord, whitted::RadiancePayload,
                   whitted::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    float t = lucent::t_hit();
    float3 hit_point = ray.origin + t * ray.direction;
    float3 i = normalize(ray.direction);
    float3 n = normalize(lucent::object_to_world_normal(attr.shading_normal));  // out of glass

    // Leaving the glass: the ray crossed t_hit * |direction| of it.
    bool leaving = dot(i, n) > 0.0f;
    float3 beer = leaving ? whitted::expf3(rec.extinction_constant * (t * length(ray.direction)))
                          : make_float3(1.0f);

    float3 result = make_float3(0.0f);
    float reflection = 1.0f;  // total internal reflection unless refraction succeeds
    float3 facing = leaving ? -n : n;  // towards the side the ray came from
    if (prd.depth <
        (rec.refraction_maxdepth < rec.max_depth ? rec.refraction_maxdepth : rec.max_depth)) {
        float eta = leaving ? rec.refraction_index : 1.0f / rec.refraction_index;
        float3 transmitted;
        if (refract(transmitted, i, facing, eta)) {
            transmitted = normalize(transmitted);
            // Schlick uses the cosine on the air side of the interface.
            float cos_theta = leaving ? dot(transmitted, n) : -dot(i, n);
            reflection = whitted::fresnel_schlick(cos_theta, rec.fresnel_exponent,
                                                  rec.fresnel_minimum, rec.fresnel_maximum);
            float importance = prd.importance * (1.0f - reflection) *
                               whitted::luminance(rec.refraction_color * beer);
            float3 refracted = rec.cutoff_color;
            if (importance > rec.importance_cutoff) {
                whitted::RadiancePayload refr;
                refr.result = make_float3(0.0f);
                refr.importance = importance;
                refr.depth = prd.depth + 1;
                float3 origin =
                    sample_common::offset_along_normal(hit_point, -facing, rec.scene_size);
                lucent::trace(rec.top_object,
                              lucent::make_ray(origin, transmitted, whitted::kRadianceRay, 0.0f,
                                               lucent::kInfinity, lucent::ray_time()),
                              refr);
                refracted = refr.result;
            }
            result += (1.0f - reflection) * rec.refraction_color * refracted;
        }
    }
    if (prd.depth <
        (rec.reflection_maxdepth < rec.max_depth ? rec.reflection_maxdepth : rec.max_depth)) {
        float importance =
            prd.importance * reflection * whitted::luminance(rec.reflection_color * beer);
        float3 reflected = rec.cutoff_color;
        if (importance > rec.importance_cutoff) {
            whitted::RadiancePayload refl;
            refl.result = make_float3(0.0f);
            refl.importance = importance;
            refl.depth = prd.depth + 1;
            float3 origin = sample_common::offset_along_normal(hit_point, facing, rec.scene_size);
            lucent::trace(rec.top_object,
                          lucent::make_ray(origin, reflect(i, n), whitted::kRadianceRay, 0.0f,
                                           lucent::kInfinity, lucent::ray_time()),
                          refl);
            reflected = refl.result;
        }
        result += reflection * rec.reflection_color * reflected;
    }
    prd.result = result * beer;
}

/// Shadow rays through glass (paper §6.1): each surface crossed lets through less light
/// at grazing angles (Fresnel), and traversal goes on for the surfaces behind. The glass
/// therefore casts a lighter shadow than the metal, darkest at its rim.
LUCENT_ANY_HIT(whitted_glass_shadow, whitted::GlassShadowRecord, whitted::ShadowPayload,
               whitted::HitAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    float3 n = normalize(attr.shading_normal);
    float cos_theta = fabsf(dot(n, normalize(ray.direction)));
    prd.attenuation *=
        make_float3(1.0f) - whitted::fresnel_schlick(cos_theta, 5.0f,
                                                     make_float3(1.0f) - rec.shadow_attenuation,
                                                     make_float3(1.0f));
    if (max_component(prd.attenuation) <= 1e-3f) {
        prd.attenuation = make_float3(0.0f);
        terminate_ray();
    } else {
        ignore_intersection();
    }
}

/// Shadow rays stop at the first opaque surface (paper §6.1: early ray termination).
LUCENT_ANY_HIT(whitted_opaque_shadow, lucent::NoRecord, whitted::ShadowPayload,
               whitted::HitAttributes) {
    prd.attenuation = make_float3(0.0f);
    terminate_ray();
}

}  // namespace whitted

// ambient_occlusion.h: the program module of the ambient-occlusion example. Each pixel
// averages `samples` camera rays, each jittered inside the pixel; where one hits a surface,
// one occlusion ray leaves it in a cosine-weighted direction, and the sample is 1 when that
// ray escapes within `radius`, 0 when it is blocked. With cosine-weighted directions that
// fraction estimates the ambient occlusion integral, (1/pi) * integral of V(w) cos(theta) dw.
//
// Random numbers: TEA (lucent/device/tea.h) of (pixel, sample index), the same on the CPU
// and the GPU, so both backends draw the same rays.
#pragma once

#include "lucent/device.h"

namespace ambient_occlusion {
// The closest-hit program calls occluded(), so the module declares it.
LUCENT_MODULE(ambient_occlusion, lucent::kUsesOccluded)

using lucent::BufferView;
using lucent::Handle;

constexpr unsigned kRay = 0;  // the one ray type: camera rays (trace) and occlusion rays (occluded)

struct Payload {
    float3 color;
    uint2 random;  // two random words for the occlusion ray's direction
};

struct CameraRecord {
    float3 eye, U, V, W;  // W: from the eye to the image centre; U, V: to its right and top edges
    unsigned samples;     // per pixel
    BufferView<float3> image;
    Handle scene;
};
LUCENT_RECORD(CameraRecord, eye, U, V, W, samples, image, scene)

LUCENT_RAY_GENERATION(camera, CameraRecord) {
    const uint3 i = lucent::launch_index(), n = lucent::launch_size();
    const unsigned pixel = i.y * n.x + i.x;
    float3 sum = make_float3(0.0f);
    for (unsigned s = 0; s < rec.samples; ++s) {
        // Four random numbers per sample: two place the ray in the pixel, two aim the
        // occlusion ray.
        const uint2 jitter = lucent::tea<16>(make_uint2(pixel, 2 * s), lucent::zafar_tea_key());
        Payload p{make_float3(0.0f),
                  lucent::tea<16>(make_uint2(pixel, 2 * s + 1), lucent::zafar_tea_key())};
        const float x = 2.0f * (i.x + lucent::tea_unit_float(jitter.x)) / n.x - 1.0f;
        const float y = 1.0f - 2.0f * (i.y + lucent::tea_unit_float(jitter.y)) / n.y;
        lucent::trace(
            rec.scene,
            lucent::make_ray(rec.eye, normalize(rec.W + x * rec.U + y * rec.V), kRay, 0.0f), p);
        sum += p.color;
    }
    rec.image[make_uint2(i.x, i.y)] = sum / float(rec.samples);
}

struct SurfaceRecord {
    float radius;   // occluders farther than this do not count
    float epsilon;  // occlusion rays start this far off the surface
    Handle scene;
};
LUCENT_RECORD(SurfaceRecord, radius, epsilon, scene)

/// A unit direction about the unit normal n, cosine-weighted: a uniform point on the disk
/// (u1, u2) lifted onto the hemisphere (Malley's method), in the basis of Duff et al. 2017,
/// "Building an Orthonormal Basis, Revisited".
LUCENT_HD inline float3 cosine_direction(float3 n, float u1, float u2) {
    const float r = sqrtf(u1), phi = 6.28318531f * u2;
    const float sign = copysignf(1.0f, n.z), a = -1.0f / (sign + n.z), b = n.x * n.y * a;
    const float3 t = make_float3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    const float3 s = make_float3(b, sign + n.y * n.y * a, -n.y);
    return r * cosf(phi) * t + r * sinf(phi) * s + sqrtf(fmaxf(0.0f, 1.0f - u1)) * n;
}

LUCENT_CLOSEST_HIT(occlusion, SurfaceRecord, Payload, lucent::TriangleAttributes) {
    const lucent::Ray& ray = lucent::current_ray();
    const float3 p = ray.origin + lucent::t_hit() * ray.direction;
    const float3 n = faceforward(normalize(lucent::object_to_world_normal(attr.geometric_normal)),
                                 ray.direction);
    const float3 d = cosine_direction(n, lucent::tea_unit_float(prd.random.x),
                                      lucent::tea_unit_float(prd.random.y));
    const bool blocked = lucent::occluded(
        rec.scene, lucent::make_ray(p + rec.epsilon * n, d, kRay, 0.0f, rec.radius));
    prd.color = make_float3(blocked ? 0.0f : 1.0f);
}

LUCENT_MISS(background, lucent::NoRecord, Payload) {
    prd.color = make_float3(0.25f, 0.3f, 0.4f);
}

}  // namespace ambient_occlusion

// first_program.h: a program module. Device code only (lucent/device.h, no standard
// library): g++ compiles it into the program for the CPU backend, and NVRTC compiles its
// text into the megakernel for the GPU.
#pragma once

#include "lucent/device.h"

namespace first_program {
LUCENT_MODULE(first_program)  // the module of the programs in this namespace

using namespace lucent;

struct Payload {  // what a ray carries
    float3 color;
};

struct Camera {
    float3 eye;
    Handle scene;
    BufferView<float3> image;
};
LUCENT_RECORD(Camera, eye, scene, image)  // the record's fields, found by name

LUCENT_RAY_GENERATION(camera, Camera) {  // runs once per launch index (pixel)
    const uint3 i = launch_index(), n = launch_size();
    const float aspect = float(n.x) / float(n.y);
    const float x = ((i.x + 0.5f) / n.x * 2 - 1) * aspect, y = 1 - (i.y + 0.5f) / n.y * 2;
    Payload p{make_float3(0.0f)};
    trace(rec.scene, make_ray(rec.eye, normalize(make_float3(x, y, -1)), 0, 0.0f), p);
    rec.image[make_uint2(i.x, i.y)] = p.color;
}

struct Shade {
    float3 color;
};
LUCENT_RECORD(Shade, color)

// The closer the triangle faces the ray, the brighter it is.
LUCENT_CLOSEST_HIT(shade, Shade, Payload, TriangleAttributes) {
    const float3 n = normalize(attr.geometric_normal);
    prd.color = rec.color * fabsf(dot(n, normalize(current_ray().direction)));
}

LUCENT_MISS(background, NoRecord, Payload) {
    prd.color = make_float3(0.1f, 0.1f, 0.2f);
}

}  // namespace first_program

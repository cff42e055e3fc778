// normals.h: the module that programs-at-run-time reads and compiles when it runs (it is
// not compiled into the program). A pinhole camera over a few triangles, each pixel the
// colour of the world normal it sees (n * 0.5 + 0.5), the background dark grey.
#pragma once

#include "lucent/device.h"

namespace normals {
LUCENT_MODULE(normals)

using namespace lucent;

struct Payload {
    float3 color;
};

struct Camera {
    float3 eye;
    Handle scene;
    BufferView<float3> image;
};
LUCENT_RECORD(Camera, eye, scene, image)

LUCENT_RAY_GENERATION(camera, Camera) {
    const uint3 i = launch_index(), n = launch_size();
    const float aspect = float(n.x) / float(n.y);
    const float x = ((i.x + 0.5f) / n.x * 2 - 1) * aspect, y = 1 - (i.y + 0.5f) / n.y * 2;
    Payload p{make_float3(0.0f)};
    trace(rec.scene, make_ray(rec.eye, normalize(make_float3(x, y, -1)), 0, 0.0f), p);
    rec.image[make_uint2(i.x, i.y)] = p.color;
}

LUCENT_CLOSEST_HIT(shade, NoRecord, Payload, TriangleAttributes) {
    const float3 n = faceforward(normalize(object_to_world_normal(attr.geometric_normal)),
                                 current_ray().direction);
    prd.color = n * 0.5f + make_float3(0.5f);
}

LUCENT_MISS(background, NoRecord, Payload) {
    prd.color = make_float3(0.1f);
}

}  // namespace normals

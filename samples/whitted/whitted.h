// The Whitted sample (OptiX paper §6.1, Fig. 7): Whitted's sphere scene, ray traced with a
// pinhole camera, Phong/metal/glass materials, shadow rays and optional adaptive
// antialiasing. Programs in whitted_programs.h; the sample (WhittedSample, registered as
// "whitted") in whitted.cpp. This header gives tests the scene's layout, and a render of the
// scene moved by a Placement (tests/scale_test.cpp).
#pragma once

#include "lucent/device/types.h"
#include "samples/placement.h"
#include "samples/sample.h"

namespace lucent::samples {

/// Where things are in the Whitted scene (world units, y up), for tests that probe the image.
struct WhittedLayout {
    float3 eye, lookat, up;
    float vfov_degrees;  // vertical field of view; the horizontal one follows the aspect
    float3 background;   // the miss program's colour
    float3 metal_center;
    float metal_radius;
    float3 metal_motion;  // motion=1: the metal sphere's displacement over the shutter [0, 1]
    float3 glass_center;
    float glass_radius;     // outer radius of the shell
    float glass_thickness;  // inner radius = glass_radius - glass_thickness
    float floor_height;
    float3 floor_anchor;              // a corner of the floor (at floor_height)
    float3 floor_edge1, floor_edge2;  // its sides from the anchor; edge1 x edge2 points up
    float3 key_light;                 // position of the first light (the only one with lights=1)
    float3 fill_lights[2];            // the second and third lights (lights=2, 3)
    float light_intensity;            // white; shared among the lights when there are several
    float ambient;                    // grey ambient light
    float glass_shadow_transmission;  // of one glass surface at normal incidence
    float glass_extinction;           // log of the glass's transmittance per unit distance
    float size;  // the scene's longest side (the floor's), which ray offsets follow
};

/// The scene's layout as modelled.
const WhittedLayout& whitted_layout();
/// The layout moved by `placement`: points and lengths transformed, the extinction per unit
/// length divided by the scale; the lights (no falloff with distance) keep their intensity.
WhittedLayout whitted_layout(const Placement& placement);

/// What the "whitted" sample renders, with its scene and its own camera moved by `placement`
/// (a camera given in `settings.camera` is taken as it is).
RenderResult render_whitted(const RenderSettings& settings, const Placement& placement);

/// Image position (x right, y down, in pixels; pixel i covers [i, i + 1)) where the world
/// point p appears in a width x height render.
float2 whitted_project(float3 p, unsigned width, unsigned height);

}  // namespace lucent::samples

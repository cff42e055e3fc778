// The fog sample's scene, built once and rendered for any camera on its orbit: the OptiX SDK
// tutorial's floor, box and crystal, point lights, the environment, and the fog box
// (Sebald, §3.1). The sample renders one frame; `lucent bench fog` renders a path. A
// Placement moves the whole scene (tests/scale_test.cpp).
#pragma once

#include <memory>
#include <string>

#include "lucent/context.h"
#include "samples/options.h"
#include "samples/placement.h"
#include "scene/scene.h"

namespace lucent::samples {

struct FogOptions {
    bool fog = true;
    float step = 0.05f;         // march step
    float height = 2.0f;        // of the fog box over the floor
    float density = 1.5f;       // extinction per unit at full noise, bottom of the box
    float noise_scale = 3.0f;   // gradient noise lattice, scene units
    bool noise = true;          // false: uniform density (tests)
    bool falloff = true;        // false: no linear falloff in y (tests)
    unsigned rounds = 2;        // TEA rounds of the noise (the paper: 2)
    unsigned device = 0, seed = 0;  // the TEA key's inputs (Sebald Fig. 4)
    unsigned max_depth = 5;
    std::string environment;  // .hdr or .exr; empty: the procedural sky
    float orbit_degrees = 0;  // the camera's place on its orbit around the scene
    float eye_height = 9.0f;
    float eye_distance = 20.0f;  // the orbit's radius, in x and z
};

/// FogOptions from the fog sample's checked option values.
FogOptions read_fog_options(const OptionValues& values);

class FogScene {
  public:
    /// The scene as modelled, moved by `placement`: geometry, lights, the fog box and the
    /// orbit's camera; the options' lengths (step, height, noise scale, eye height and
    /// distance) are in the modelled scene's units, and the patterns and the fog's noise move
    /// with it. The image is that of the unmoved scene, up to rounding.
    FogScene(const FogOptions& options, unsigned width, unsigned height, const ContextOptions& ctx,
             const Placement& placement = {});
    ~FogScene();

    /// Places the camera at `orbit_degrees` around the scene and launches; returns the report.
    const LaunchReport& render(float orbit_degrees);
    /// Launches with any camera (the viewer's); returns the report.
    const LaunchReport& render(const scene::Camera& camera);
    /// The camera at `orbit_degrees` on the orbit of the options' height and distance (placed).
    scene::Camera orbit_camera(float orbit_degrees) const;
    Context& context();
    const Buffer& output() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> m;
};

}  // namespace lucent::samples

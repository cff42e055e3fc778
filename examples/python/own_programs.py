#!/usr/bin/env python3
"""A renderer of your own, written in Python: ambient occlusion of a torus on a floor, its
programs in a C++ string that Context.add_module compiles at run time (the system's C++
compiler for the CPU, NVRTC for the GPU), its scene built from numpy arrays.

    own_programs.py [--backend auto|cpu|cuda] [--size W H] [--samples N] [--out image.npy]
"""
import argparse

import numpy as np

import lucent

# The module: one ray-generation program (a pinhole camera, `samples` jittered rays per
# pixel), one closest hit (a cosine-weighted occlusion ray through occluded()), one miss.
# Random numbers come from TEA of (pixel, sample), so every backend draws the same rays.
PROGRAMS = r"""
#include "lucent/device.h"

namespace own_ao {
LUCENT_MODULE(own_ao, lucent::kUsesOccluded)  // its closest hit calls occluded()
using namespace lucent;

struct Payload { float value; uint2 random; };

struct Camera { float3 eye, U, V, W; unsigned samples; BufferView<float> image; Handle scene; };
LUCENT_RECORD(Camera, eye, U, V, W, samples, image, scene)

LUCENT_RAY_GENERATION(camera, Camera) {
    const uint3 i = launch_index(), n = launch_size();
    const unsigned pixel = i.y * n.x + i.x;
    float sum = 0.0f;
    for (unsigned s = 0; s < rec.samples; ++s) {
        const uint2 jitter = tea<16>(make_uint2(pixel, 2 * s), zafar_tea_key());
        Payload p{0.0f, tea<16>(make_uint2(pixel, 2 * s + 1), zafar_tea_key())};
        const float x = 2.0f * (i.x + tea_unit_float(jitter.x)) / n.x - 1.0f;
        const float y = 1.0f - 2.0f * (i.y + tea_unit_float(jitter.y)) / n.y;
        trace(rec.scene, make_ray(rec.eye, normalize(rec.W + x * rec.U + y * rec.V), 0, 0.0f), p);
        sum += p.value;
    }
    rec.image[make_uint2(i.x, i.y)] = sum / float(rec.samples);
}

struct Surface { float radius; Handle scene; };
LUCENT_RECORD(Surface, radius, scene)

LUCENT_CLOSEST_HIT(occlusion, Surface, Payload, TriangleAttributes) {
    const Ray& ray = current_ray();
    const float3 p = ray.origin + t_hit() * ray.direction;
    const float3 n = faceforward(normalize(attr.geometric_normal), ray.direction);
    // A cosine-weighted direction about n: Malley's method in Duff et al.'s basis (2017).
    const float u1 = tea_unit_float(prd.random.x), u2 = tea_unit_float(prd.random.y);
    const float r = sqrtf(u1), phi = 6.28318531f * u2;
    const float sign = copysignf(1.0f, n.z), a = -1.0f / (sign + n.z), b = n.x * n.y * a;
    const float3 t = make_float3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    const float3 s = make_float3(b, sign + n.y * n.y * a, -n.y);
    const float3 d = r * cosf(phi) * t + r * sinf(phi) * s + sqrtf(fmaxf(0.0f, 1.0f - u1)) * n;
    prd.value = occluded(rec.scene, make_ray(p + 1e-3f * n, d, 0, 0.0f, rec.radius)) ? 0.0f : 1.0f;
}

LUCENT_MISS(sky, NoRecord, Payload) { prd.value = 1.0f; }
}
"""


def torus_on_floor(rings=48, sides=24, R=1.0, r=0.35):
    """A torus lying on the plane y = 0 and a 6x6 floor square under it."""
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, rings, endpoint=False),
                       np.linspace(0, 2 * np.pi, sides, endpoint=False), indexing="ij")
    ring = R + r * np.cos(v)
    torus = np.stack([ring * np.cos(u), r * np.sin(v) + r, ring * np.sin(u)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(rings), np.arange(sides), indexing="ij")
    a, b = i * sides + j, ((i + 1) % rings) * sides + j
    c, d = ((i + 1) % rings) * sides + (j + 1) % sides, i * sides + (j + 1) % sides
    quads = np.stack([a, b, c, d], -1).reshape(-1, 4)
    floor = np.array([[-3, 0, -3], [3, 0, -3], [3, 0, 3], [-3, 0, 3]], float)
    vertices = np.concatenate([torus, floor]).astype(np.float32)
    n = len(torus)
    faces = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]],
                            [[n, n + 2, n + 1], [n, n + 3, n + 2]]]).astype(np.uint32)
    return vertices, faces


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--backend", default="auto", choices=["auto", "cpu", "cuda"])
    parser.add_argument("--size", type=int, nargs=2, default=[320, 240], metavar=("W", "H"))
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--out", default="own-programs.npy")
    args = parser.parse_args()

    ctx = lucent.Context(backend=args.backend)
    ctx.add_module(PROGRAMS, name="own_ao.h")  # compiled now, or loaded from the cache
    ctx.set_ray_type(0, "radiance", payload="own_ao::Payload")
    ctx.set_ray_generation_program(0, ctx.create_program("camera"))
    ctx.set_miss_program(0, ctx.create_program("sky"))

    vertices, faces = torus_on_floor()
    vertex_buffer = ctx.create_buffer("input", "float3", len(vertices))
    vertex_buffer.upload(vertices)
    index_buffer = ctx.create_buffer("input", "uint3", len(faces))
    index_buffer.upload(faces)
    mesh = ctx.create_geometry_triangles()
    mesh.vertices, mesh.indices = vertex_buffer, index_buffer
    material = ctx.create_material()
    material.set_closest_hit(0, ctx.create_program("occlusion"))
    material["radius"] = 1.5
    instance = ctx.create_geometry_instance()
    instance.geometry = mesh
    instance.add_material(material)
    scene = ctx.create_geometry_group()
    scene.add_child(instance)

    # A camera above and in front of the torus, looking at its centre.
    width, height = args.size
    eye, look = np.array([0.0, 2.2, 4.0]), np.array([0.0, 0.2, 0.0])
    W = look - eye
    U = np.cross(W, [0, 1, 0])
    U *= np.linalg.norm(W) * np.tan(np.radians(20)) * width / height / np.linalg.norm(U)
    V = np.cross(U, W)
    V *= np.linalg.norm(W) * np.tan(np.radians(20)) / np.linalg.norm(V)
    image = ctx.create_buffer("output", "float", (width, height))
    ctx["eye"], ctx["U"], ctx["V"], ctx["W"] = eye, U, V, W
    ctx["samples"], ctx["image"], ctx["scene"] = args.samples, image, scene
    report = ctx.launch(0, width, height)

    ao = image.download()  # (height, width) float32 in [0, 1]
    print(f"backend: {ctx.backend}; {width}x{height}, {args.samples} samples per pixel "
          f"in {report.launch_ms:.0f} ms")
    np.save(args.out, ao)
    print(f"wrote {args.out}")
    # The floor under the torus's inner rim is in its shadow; the sky is unoccluded.
    if not (ao.min() < 0.5 and ao.max() == 1.0 and 0.0 <= ao.min()):
        raise SystemExit("own_programs.py: the image should show occlusion under the torus")


if __name__ == "__main__":
    main()

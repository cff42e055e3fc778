#!/usr/bin/env python3
"""A launch of your own: the first program of docs/programming-model.md with its host side
in Python. Its module (examples/first-program/first_program.h) is compiled into the
extension; this script builds the scene graph, sets the variables and launches.

    first_launch.py [--backend auto|cpu|cuda] [--out image.npy]
"""
import argparse

import numpy as np

import lucent


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--backend", default="auto", choices=["auto", "cpu", "cuda"])
    parser.add_argument("--out", default="first-launch.npy")
    args = parser.parse_args()

    ctx = lucent.Context(backend=args.backend)
    ctx.add_module("first_program")  # a module compiled into the extension: lucent.modules()
    camera = ctx.create_program("camera")
    ctx.set_ray_type(0, "radiance", payload=camera.module + "::Payload")
    ctx.set_ray_generation_program(0, camera)  # entry point 0
    ctx.set_miss_program(0, ctx.create_program("background"))

    # The scene: one triangle, in one geometry instance with one material.
    vertices = ctx.create_buffer("input", "float3", 3)
    vertices.upload(np.array([[-1, -1, -2], [1, -1, -2.5], [0, 1, -1.5]], np.float32))
    triangle = ctx.create_geometry_triangles()
    triangle.vertices = vertices
    material = ctx.create_material()
    material.set_closest_hit(0, ctx.create_program("shade"))
    material["color"] = (1, 0.5, 0.2)
    instance = ctx.create_geometry_instance()
    instance.geometry = triangle
    instance.add_material(material)
    scene = ctx.create_geometry_group()
    scene.add_child(instance)

    # The camera's variables, and the launch: one index per pixel.
    width, height = 640, 480
    image = ctx.create_buffer("output", "float3", (width, height))
    ctx["eye"] = (0, 0, 0)
    ctx["scene"] = scene  # a node becomes a Handle
    ctx["image"] = image
    report = ctx.launch(0, width, height)

    pixels = image.numpy()  # (480, 640, 3), a view of the buffer: no copy
    lit = np.count_nonzero(pixels[..., 0] > 0.2)
    print(f"backend: {ctx.backend}")
    print(f"the triangle covers {lit} of {width * height} pixels ({report.launch_ms:.1f} ms)")
    with open(args.out, "wb") as f:
        np.save(f, pixels)
    print(f"wrote {args.out} ({width}x{height})")
    if not 1000 < lit < width * height:
        raise SystemExit("first_launch.py: the triangle should cover part of the image")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Writes a glTF 2.0 scene of N instances of one sphere mesh on a grid, for measuring what
instancing saves (docs/scenes.md, "Instancing: memory"): with --flatten, the same scene as
one mesh holding every copy's triangles already transformed (what a loader without
instancing would build). A ground quad, a camera and a point light come with it; the
buffer is embedded as base64, so the file stands alone.

  python3 scripts/make_instanced_gltf.py --instances 1000 --out /tmp/spheres.gltf
  python3 scripts/make_instanced_gltf.py --instances 1000 --flatten --out /tmp/flat.glb

An --out ending in .glb writes the binary container (the buffer as its BIN chunk, no base64:
what a large flattened scene should be measured as, the parser's cost being the file's).
"""
import argparse
import base64
import json
import math
import struct


def sphere(rings, segments):
    """A UV sphere of radius 1: positions and triangles (counter-clockwise from outside)."""
    positions, triangles = [], []
    for r in range(rings + 1):
        theta = math.pi * r / rings
        for s in range(segments + 1):
            phi = 2 * math.pi * s / segments
            positions.append((math.sin(theta) * math.cos(phi), math.cos(theta),
                              math.sin(theta) * math.sin(phi)))
    for r in range(rings):
        for s in range(segments):
            a = r * (segments + 1) + s
            b = a + segments + 1
            triangles += [(a, a + 1, b), (a + 1, b + 1, b)]
    return positions, triangles


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--instances", type=int, default=1000)
    parser.add_argument("--rings", type=int, default=32, help="sphere rings (2 x rings x "
                        "segments triangles)")
    parser.add_argument("--segments", type=int, default=64)
    parser.add_argument("--flatten", action="store_true",
                        help="one mesh with every copy's triangles, no instancing")
    parser.add_argument("--out", required=True)
    args = parser.parse_args()

    side = math.ceil(math.sqrt(args.instances))
    spacing = 3.0
    offsets = [((i % side - (side - 1) / 2) * spacing, 1.0, (i // side - (side - 1) / 2) * spacing)
               for i in range(args.instances)]
    positions, triangles = sphere(args.rings, args.segments)
    if args.flatten:
        flat_p, flat_t = [], []
        for o in offsets:
            base = len(flat_p)
            flat_p += [(p[0] + o[0], p[1] + o[1], p[2] + o[2]) for p in positions]
            flat_t += [(a + base, b + base, c + base) for a, b, c in triangles]
        positions, triangles = flat_p, flat_t
    half = side * spacing / 2 + spacing
    ground_p = [(-half, 0, -half), (half, 0, -half), (half, 0, half), (-half, 0, half)]
    ground_t = [(0, 2, 1), (0, 3, 2)]

    blob = bytearray()
    views, accessors = [], []

    def add(values, fmt, target, gltf_type, component):
        offset = len(blob)
        for v in values:
            blob.extend(struct.pack("<" + fmt, *v))
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob) - offset,
                      "target": target})
        accessor = {"bufferView": len(views) - 1, "componentType": component,
                    "count": len(values), "type": gltf_type}
        if gltf_type == "VEC3" and component == 5126:
            accessor["min"] = [min(v[k] for v in values) for k in range(3)]
            accessor["max"] = [max(v[k] for v in values) for k in range(3)]
        accessors.append(accessor)
        return len(accessors) - 1

    sphere_pos = add(positions, "3f", 34962, "VEC3", 5126)
    sphere_idx = add([(i,) for t in triangles for i in t], "I", 34963, "SCALAR", 5125)
    ground_pos = add(ground_p, "3f", 34962, "VEC3", 5126)
    ground_idx = add([(i,) for t in ground_t for i in t], "I", 34963, "SCALAR", 5125)

    if args.flatten:
        sphere_nodes = [{"name": "spheres", "mesh": 0}]
    else:
        sphere_nodes = [{"name": f"sphere{i}", "mesh": 0, "translation": list(o)}
                        for i, o in enumerate(offsets)]
    nodes = [{"name": "ground", "mesh": 1},
             {"name": "camera", "camera": 0, "translation": [0, half * 0.9, half * 1.6],
              # a rotation about x of -30 degrees: looking down at the grid
              "rotation": [-math.sin(math.radians(15)), 0, 0, math.cos(math.radians(15))]},
             {"name": "light", "translation": [0, half * 2, half],
              "extensions": {"KHR_lights_punctual": {"light": 0}}}] + sphere_nodes
    gltf = {
        "asset": {"version": "2.0", "generator": "lucent scripts/make_instanced_gltf.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1, 1, 1], "intensity": 4 * half * half}]}},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.1}}],
        "meshes": [
            {"name": "sphere", "primitives": [{"attributes": {"POSITION": sphere_pos},
                                               "indices": sphere_idx, "material": 0}]},
            {"name": "ground", "primitives": [{"attributes": {"POSITION": ground_pos},
                                               "indices": ground_idx, "material": 1}]}],
        "materials": [
            {"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.1, 1],
                                                      "metallicFactor": 0, "roughnessFactor": 0.5}},
            {"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1],
                                                       "metallicFactor": 0, "roughnessFactor": 1}}],
        "buffers": [{"byteLength": len(blob)}],
        "bufferViews": views,
        "accessors": accessors,
    }
    if args.out.endswith(".glb"):
        text = json.dumps(gltf).encode()
        text += b" " * (-len(text) % 4)
        blob.extend(b"\0" * (-len(blob) % 4))
        with open(args.out, "wb") as f:
            f.write(b"glTF" + struct.pack("<II", 2, 12 + 8 + len(text) + 8 + len(blob)))
            f.write(struct.pack("<I", len(text)) + b"JSON" + text)
            f.write(struct.pack("<I", len(blob)) + b"BIN\0" + bytes(blob))
    else:
        gltf["buffers"][0]["uri"] = ("data:application/octet-stream;base64," +
                                     base64.b64encode(bytes(blob)).decode())
        with open(args.out, "w") as f:
            json.dump(gltf, f)
    drawn = len(triangles) * (1 if args.flatten else args.instances) + 2
    print(f"{args.out}: {args.instances} spheres of {len(sphere(args.rings, args.segments)[1])} "
          f"triangles ({'flattened' if args.flatten else 'instanced'}), {drawn} triangles drawn")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""TriangleMesh.intersect and .occluded on the ray sets of `lucent bench rays`, beside it.

Makes shared/BENCH.md's primary, shadow and diffuse rays for a scene's cameras.txt viewpoint
in numpy (the formulas of bench/bench_rays.cpp, operation for operation in float32), times
mesh.intersect / mesh.occluded on them (the median of --repeat passes after a warm-up, each
pass the whole call: arrays in, engine launch, arrays out), and runs `lucent bench rays`
on the same scene through lucent.bench_rays, alternating the two --rounds times on the same
machine. Prints both engines' Mrays/s, the ratio per ray kind (the median of the rounds'
ratios) and both engines' checksums, which agree when the rays are the same.

    bench_rays.py --scene ../shared/scenes/sponza.obj [--backend cpu]

With --backend cuda the Python figures include the copies to the GPU and back; `lucent
bench rays --backend cuda` times its kernels alone (at its own 3840x2160; pass --size
3840x2160 for the same rays).
"""
import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import lucent

F = np.float32


def find_camera(scene):
    """The scene's line of cameras.txt beside it or one directory up (bench_camera.cpp)."""
    scene = Path(scene).resolve()
    for folder in (scene.parent, scene.parent.parent):
        listing = folder / "cameras.txt"
        if not listing.exists():
            continue
        relative = scene.relative_to(folder).as_posix()
        for line in listing.read_text().splitlines():
            fields = line.split()
            if not fields or fields[0].startswith("#") or fields[0] != relative:
                continue
            vec = [np.array([F(c) for c in f.split(",")], F) for f in fields[1:4]]
            return vec[0], vec[1], vec[2], F(fields[4]), np.array([F(c) for c in fields[5].split(",")], F)
    sys.exit(f"bench_rays.py: no viewpoint for {scene} in cameras.txt")


def dot(a, b):
    return (a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]) + a[..., 2] * b[..., 2]


def cross(a, b):
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                     a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def normalize(a):
    return a * (F(1) / np.sqrt(dot(a, a)))[..., None]


def primary_rays(eye, look, up, fov, w, h):
    fwd = normalize(look - eye)
    right = normalize(cross(fwd, up))
    up2 = cross(right, fwd)
    t = F(np.tan(np.float64(F(fov / F(2) * F(3.14159265358979323846) / F(180)))))
    a = F(w) / F(h)
    x = np.arange(w, dtype=F)[None, :].repeat(h, 0).ravel()
    y = np.arange(h, dtype=F)[:, None].repeat(w, 1).ravel()
    u = ((F(2) * (x + F(0.5))) / F(w) - F(1)) * t * a
    v = (F(1) - (F(2) * (y + F(0.5))) / F(h)) * t
    d = normalize((fwd + u[:, None] * right) + v[:, None] * up2)
    return np.ascontiguousarray(np.broadcast_to(eye, d.shape)), np.ascontiguousarray(d, F)


def hash32(a):
    a = a.astype(np.uint32)
    a ^= a >> np.uint32(16)
    a *= np.uint32(0x7FEB352D)
    a ^= a >> np.uint32(15)
    a *= np.uint32(0x846CA68B)
    a ^= a >> np.uint32(16)
    return a


def secondary_rays(origins, directions, hits, light):
    """Shadow and diffuse rays from the primary hits (bench_rays.cpp's secondary_rays)."""
    pixel = np.nonzero(hits.prim >= 0)[0]
    d = directions[pixel]
    p = origins[pixel] + hits.t[pixel][:, None] * d
    n = hits.normal[pixel].copy()  # normalize(cross(v1 - v0, v2 - v0)), as the benchmark's
    n[dot(n, d) > 0] *= F(-1)
    o = p + F(1e-3) * n
    to_light = light - o
    dist = np.sqrt(dot(to_light, to_light))
    shadow = (o, to_light / dist[:, None], dist)
    h1 = hash32(np.uint32(2) * pixel.astype(np.uint32) + np.uint32(1))
    h2 = hash32(h1)
    u1 = (h1 >> np.uint32(8)).astype(F) / F(16777216)
    u2 = (h2 >> np.uint32(8)).astype(F) / F(16777216)
    r = np.sqrt(u1)
    phi = F(2) * F(3.14159265358979323846) * u2
    cos_phi = np.cos(phi.astype(np.float64)).astype(F)  # correctly rounded, as cosf nearly always is
    sin_phi = np.sin(phi.astype(np.float64)).astype(F)
    axis = np.where((np.abs(n[:, 0]) > F(0.5))[:, None], np.array([0, 1, 0], F), np.array([1, 0, 0], F))
    tt = normalize(cross(n, axis))
    bb = cross(n, tt)
    dr = normalize((tt * (r * cos_phi)[:, None] + bb * (r * sin_phi)[:, None]) +
                   n * np.sqrt(np.maximum(F(0), F(1) - u1))[:, None])
    diffuse = (o, np.ascontiguousarray(dr, F))
    return shadow, diffuse


def timed(fn, count, repeat):
    fn()  # warm-up: the first call compiles the scene and builds the BVH
    seconds = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        seconds.append(time.perf_counter() - start)
    return count / statistics.median(seconds) * 1e-6


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=os.path.join(os.environ.get("LUCENT_SCENES_DIR", "../shared/scenes"), "sponza.obj"))
    parser.add_argument("--backend", default="cpu", choices=["cpu", "cuda", "auto"])
    parser.add_argument("--size", default=None, help="WxH (default: 1024x768 on the CPU, 3840x2160 on the GPU)")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--threads", type=int, default=0)
    args = parser.parse_args()
    size = args.size or ("1024x768" if args.backend == "cpu" else "3840x2160")
    w, h = (int(s) for s in size.split("x"))

    eye, look, up, fov, light = find_camera(args.scene)
    mesh = lucent.TriangleMesh.load(args.scene, backend=args.backend, threads=args.threads)
    origins, directions = primary_rays(eye, look, up, fov, w, h)
    hits = mesh.intersect(origins, directions)
    (so, sd, st), (do, dd) = secondary_rays(origins, directions, hits, light)
    blocked = mesh.occluded(so, sd, st)
    bounce = mesh.intersect(do, dd)
    ours = {
        "primary": dict(hits=int((hits.prim >= 0).sum()), sum_t=float(hits.t[hits.prim >= 0].astype(np.float64).sum())),
        "shadow": dict(rays=len(st), occluded=int(blocked.sum())),
        "diffuse": dict(rays=len(dd), hits=int((bounce.prim >= 0).sum()), sum_t=float(bounce.t[bounce.prim >= 0].astype(np.float64).sum())),
    }
    print(f"scene {args.scene}: {mesh.triangle_count} triangles, {w}x{h}, {mesh.backend}, "
          f"lucent {lucent.__version__} from {Path(lucent.__file__).parent}")

    # `lucent bench rays --json`'s document, measured in this process (Embree beside it).
    def bench_rays():
        return lucent.bench_rays(args.scene, size=(w, h), repeat=args.repeat, threads=args.threads,
                                 backend="cpu" if args.backend == "cpu" else "cuda")
    rates = {k: [] for k in ("primary", "shadow", "diffuse")}
    bench = {k: [] for k in rates}
    embree = {k: [] for k in rates}
    kernel = {k: [] for k in rates}  # the engine's megakernel alone (CUDA events), GPU only
    calls = {"primary": (lambda: mesh.intersect(origins, directions), len(origins)),
             "shadow": (lambda: mesh.occluded(so, sd, st), len(st)),
             "diffuse": (lambda: mesh.intersect(do, dd), len(dd))}
    for _ in range(args.rounds):
        for k, (call, count) in calls.items():
            rates[k].append(timed(call, count, args.repeat))
            if mesh.last_launch.kernel_ms > 0:
                kernel[k].append(count / mesh.last_launch.kernel_ms * 1e-3)
        result = bench_rays()
        engine = result["lucent"]
        for k in rates:
            bench[k].append(engine[k]["mrays"])
            if "embree" in result:
                embree[k].append(result["embree"][k]["mrays"])
    print(f"{'rays':8} {'TriangleMesh':>14} {'bench rays':>12} {'ratio':>7} {'embree':>8}   checksums (python | bench rays)")
    for k in rates:
        ratio = statistics.median(p / b for p, b in zip(rates[k], bench[k]))
        emb = f"{statistics.median(embree[k]):8.2f}" if embree[k] else "       -"
        theirs = {key: engine[k][key] for key in ours[k]}
        print(f"{k:8} {statistics.median(rates[k]):9.2f} Mr/s {statistics.median(bench[k]):7.2f} Mr/s "
              f"{100 * ratio:6.1f}% {emb}   {ours[k]} | {theirs}")
        if kernel[k]:
            print(f"{'':8} the engine's megakernel alone: {statistics.median(kernel[k]):.1f} Mr/s "
                  "(TriangleMesh's figure adds the copies to the GPU and back)")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Ray queries on numpy arrays: line of sight and distances against a mesh.

A torus made in numpy (or an OBJ file given with --mesh), 100,000 random segments tested for
line of sight with TriangleMesh.occluded, and 100,000 random rays' first hits with
TriangleMesh.intersect; then the same mesh moved (TriangleMesh.update) and queried again.

    ray_queries.py [--mesh FILE.obj] [--backend auto|cpu|cuda] [--out answers.npz]
"""
import argparse
import time

import numpy as np

import lucent


def torus(rings=64, sides=32, R=1.0, r=0.4):
    """A torus around the y axis as (vertices, indices)."""
    u = np.repeat(np.arange(rings), sides) * (2 * np.pi / rings)
    v = np.tile(np.arange(sides), rings) * (2 * np.pi / sides)
    d = R + r * np.cos(v)
    vertices = np.stack([d * np.cos(u), r * np.sin(v), d * np.sin(u)], axis=1).astype(np.float32)
    i, j = np.divmod(np.arange(rings * sides), sides)
    a, b = i * sides + j, ((i + 1) % rings) * sides + j
    c, e = ((i + 1) % rings) * sides + (j + 1) % sides, i * sides + (j + 1) % sides
    indices = np.concatenate([np.stack([a, e, c], 1), np.stack([a, c, b], 1)]).astype(np.uint32)
    return vertices, indices


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", help="an OBJ file (default: a torus)")
    parser.add_argument("--backend", default="auto", choices=["auto", "cpu", "cuda"])
    parser.add_argument("--out", help="write the answers to this .npz file")
    args = parser.parse_args()

    if args.mesh:
        mesh = lucent.TriangleMesh.load(args.mesh, backend=args.backend)
        lo, hi = -2.0, 2.0
    else:
        vertices, indices = torus()
        mesh = lucent.TriangleMesh(vertices, indices, backend=args.backend)
        lo, hi = vertices.min(0) - 0.5, vertices.max(0) + 0.5
    print(f"mesh: {mesh.triangle_count} triangles on {mesh.backend}")

    rng = np.random.default_rng(7)
    n = 100_000
    a = rng.uniform(lo, hi, (n, 3)).astype(np.float32)
    b = rng.uniform(lo, hi, (n, 3)).astype(np.float32)
    start = time.perf_counter()
    blocked = mesh.occluded(a, b - a, tmax=1.0)  # the segment a -> b is t in (0, 1)
    print(f"line of sight: {np.count_nonzero(~blocked)} of {n} segments clear "
          f"({1e3 * (time.perf_counter() - start):.1f} ms with the first query's set-up)")

    origins = rng.uniform(lo, hi, (n, 3)).astype(np.float32)
    directions = rng.normal(size=(n, 3)).astype(np.float32)
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    start = time.perf_counter()
    hits = mesh.intersect(origins, directions)
    ms = 1e3 * (time.perf_counter() - start)
    hit = hits.prim >= 0
    print(f"distance: {hit.sum()} of {n} rays hit, mean distance {hits.t[hit].mean():.4f} ({ms:.1f} ms)")
    # The hit points from t, and from the barycentrics: the same points.
    points = origins[hit] + hits.t[hit, None] * directions[hit]
    print(f"hit points: {points.shape[0]}, facing the ray: "
          f"{np.mean(np.sum(hits.normal[hit] * directions[hit], axis=1) < 0):.2f} of them")

    if not args.mesh:
        mesh.update(vertices * np.float32(1.5))  # the torus grown: refitted, not rebuilt
        grown = mesh.intersect(origins, directions)
        print(f"grown torus: {np.count_nonzero(grown.prim >= 0)} of {n} rays hit")
    if args.out:
        with open(args.out, "wb") as f:
            np.savez(f, blocked=blocked, t=hits.t, prim=hits.prim)
        print(f"wrote {args.out}")
    if not (0 < hit.sum() < n and 0 < blocked.sum() < n):
        raise SystemExit("ray_queries.py: expected some rays to hit and some to miss")


if __name__ == "__main__":
    main()

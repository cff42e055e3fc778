"""A brute-force ray-triangle reference in numpy: Moller-Trumbore (Moller and Trumbore 1997,
"Fast, minimum storage ray-triangle intersection") in float64 over every ray and triangle,
with what the tests need to tell a clear answer from one that rounding may decide."""
import numpy as np


def random_mesh(rng, vertices=300, triangles=400):
    """Triangles between random points of the unit cube [-1, 1]^3 (shared vertices)."""
    v = rng.uniform(-1, 1, (vertices, 3)).astype(np.float32)
    i = np.stack([rng.choice(vertices, 3, replace=False) for _ in range(triangles)]).astype(np.uint32)
    return v, i


def random_rays(rng, count):
    """Rays from a sphere of radius 3 around the unit cube [-1, 1]^3 towards points in it
    (most hit, at distances of 1.3 or more, where float32 gives t to 1e-5 relative), some
    pointing away, of random lengths (t is in units of the direction's length)."""
    o = rng.normal(size=(count, 3))
    o *= 3 / np.linalg.norm(o, axis=1, keepdims=True)
    target = rng.uniform(-1, 1, (count, 3))
    d = (target - o) * rng.uniform(0.2, 3.0, (count, 1))
    away = rng.random(count) < 0.15
    d[away] *= -1
    return o.astype(np.float32), d.astype(np.float32)


def all_hits(vertices, indices, origins, directions):
    """t, u, v of every ray (rows) against every triangle (columns), in float64; t is nan
    where the ray is parallel to the triangle's plane."""
    v = vertices.astype(np.float64)
    p0, p1, p2 = v[indices[:, 0]], v[indices[:, 1]], v[indices[:, 2]]
    e1, e2 = p1 - p0, p2 - p0
    o = origins.astype(np.float64)[:, None, :]
    d = directions.astype(np.float64)[:, None, :]
    pvec = np.cross(d, e2[None])
    det = np.sum(e1[None] * pvec, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        tvec = o - p0[None]
        u = np.sum(tvec * pvec, axis=-1) * inv
        qvec = np.cross(tvec, e1[None])
        w = np.sum(d * qvec, axis=-1) * inv
        t = np.sum(e2[None] * qvec, axis=-1) * inv
    t[np.abs(det) < 1e-300] = np.nan
    return t, u, w


def unit_normals(vertices, indices):
    v = vertices.astype(np.float64)
    n = np.cross(v[indices[:, 1]] - v[indices[:, 0]], v[indices[:, 2]] - v[indices[:, 0]])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


class Reference:
    """The closest hit per ray, and which rays' answers rounding cannot change: no
    triangle within `edge` (barycentric) of an edge of the ray, and the closest hit clear of
    the next by `gap` relative."""

    def __init__(self, vertices, indices, origins, directions, tmin=0.0, tmax=np.inf,
                 edge=2e-5, gap=2e-5):
        self.triangle_count = len(indices)
        t, u, v = all_hits(vertices, indices, origins, directions)
        tmin = np.broadcast_to(np.asarray(tmin, np.float64), (len(origins),))[:, None]
        tmax = np.broadcast_to(np.asarray(tmax, np.float64), (len(origins),))[:, None]
        margin = np.minimum(np.minimum(u, v), 1 - u - v)  # > 0 inside, < 0 outside
        in_range = (t > tmin) & (t < tmax)
        hit = in_range & (margin > 0)
        t_hit = np.where(hit, t, np.inf)
        self.prim = np.where(hit.any(axis=1), np.argmin(t_hit, axis=1), -1)
        rows = np.arange(len(origins))
        self.t = t_hit[rows, np.maximum(self.prim, 0)]
        self.t[self.prim < 0] = np.inf
        self.uv = np.stack([u[rows, np.maximum(self.prim, 0)], v[rows, np.maximum(self.prim, 0)]], axis=1)
        self.normal = unit_normals(vertices, indices)[np.maximum(self.prim, 0)]
        # Unclear: a triangle whose plane is crossed about in range near one of its edges, a
        # second hit about as close as the first, or a hit about at tmin or tmax.
        slack = gap * (1 + np.abs(t))
        about_in_range = (t > tmin - slack) & (t < tmax + slack)
        near_edge = about_in_range & (np.abs(margin) < edge)
        second = np.sort(t_hit, axis=1)[:, 1] if t_hit.shape[1] > 1 else np.full(len(origins), np.inf)
        with np.errstate(invalid="ignore"):  # inf - inf where a ray has no hit
            close_second = (self.prim >= 0) & (second - self.t <= gap * np.abs(self.t))
        near_bounds = (margin > -edge) & ((np.abs(t - tmin) <= slack) | (np.abs(t - tmax) <= slack))
        self.clear = ~(near_edge.any(axis=1) | close_second | near_bounds.any(axis=1))
        self.blocked = self.prim >= 0

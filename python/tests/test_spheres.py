"""Built-in spheres from Python: a GeometrySpheres of numpy centres and radii, hit programs
written in a module string reading BuiltinSphereAttributes, the answers checked against
numpy's closed form, and misuse refused by name."""
import numpy as np
import pytest

import lucent
from conftest import BACKEND

SPHERE_MODULE = """
#include "lucent/device.h"
namespace py_spheres {
LUCENT_MODULE(py_spheres)
using namespace lucent;

struct Payload { float t; float nz; unsigned prim; unsigned entering; };
struct Camera { Handle scene; BufferView<float4> image; };
LUCENT_RECORD(Camera, scene, image)

// One ray per pixel along +z from the plane z = 0, x and y in [-4, 4].
LUCENT_RAY_GENERATION(camera, Camera) {
    const uint3 i = launch_index(), n = launch_size();
    const float x = ((i.x + 0.5f) / n.x * 2 - 1) * 4, y = ((i.y + 0.5f) / n.y * 2 - 1) * 4;
    Payload p{-1.0f, 0.0f, 0u, 0u};
    trace(rec.scene, make_ray(make_float3(x, y, 0), make_float3(0, 0, 1), 0, 0.0f), p);
    rec.image[make_uint2(i.x, i.y)] = make_float4(p.t, p.nz, float(p.prim), float(p.entering));
}
LUCENT_CLOSEST_HIT(hit, NoRecord, Payload, BuiltinSphereAttributes) {
    prd.t = t_hit();
    prd.nz = attr.normal.z;
    prd.prim = primitive_index();
    prd.entering = attr.entering;
}
LUCENT_MISS(nothing, NoRecord, Payload) { prd.t = -1.0f; }
}
"""

CENTRES = np.array([[-2, -2, 10], [2, 1, 12], [0, 3, 8]], np.float32)
RADII = np.array([1.5, 2.0, 0.75], np.float32)


def sphere_scene(ctx, centres=CENTRES, radii=RADII):
    ctx.add_module(SPHERE_MODULE)
    ctx.set_ray_type(0, "probe", payload="py_spheres::Payload")
    ctx.set_ray_generation_program(0, ctx.create_program("camera", "py_spheres"))
    ctx.set_miss_program(0, ctx.create_program("nothing", "py_spheres"))
    spheres = ctx.create_geometry_spheres()
    c = ctx.create_buffer("input", "float3", len(centres))
    c.upload(centres)
    r = ctx.create_buffer("input", "float", len(radii))
    r.upload(radii)
    spheres.centers, spheres.radii = c, r
    material = ctx.create_material()
    material.set_closest_hit(0, ctx.create_program("hit", "py_spheres"))
    instance = ctx.create_geometry_instance()
    instance.geometry = spheres
    instance.add_material(material)
    scene = ctx.create_geometry_group()
    scene.add_child(instance)
    return scene, spheres


def expected(size):
    w, h = size
    x = ((np.arange(w) + 0.5) / w * 2 - 1) * 4
    y = ((np.arange(h) + 0.5) / h * 2 - 1) * 4
    X, Y = np.meshgrid(x, y)
    best = np.full(X.shape, np.inf)
    prim = np.full(X.shape, -1)
    edge = np.zeros(X.shape, bool)  # within 1e-3 of a silhouette: may go either way in float
    for k, (c, r) in enumerate(zip(CENTRES.astype(np.float64), RADII.astype(np.float64))):
        d2 = (X - c[0]) ** 2 + (Y - c[1]) ** 2
        edge |= np.abs(np.sqrt(d2) - r) < 1e-3
        t = c[2] - np.sqrt(np.maximum(r * r - d2, 0))
        hit = (d2 < r * r) & (t < best)
        best = np.where(hit, t, best)
        prim = np.where(hit, k, prim)
    return best, prim, edge


def test_spheres_render_as_the_closed_form_says():
    ctx = lucent.Context(backend=BACKEND)
    scene, _ = sphere_scene(ctx)
    size = (48, 40)
    image = ctx.create_buffer("output", "float4", size)
    ctx["scene"], ctx["image"] = scene, image
    ctx.launch(0, *size)
    out = image.download()
    best, prim, edge = expected(size)
    hit = prim >= 0
    assert np.array_equal((out[..., 0] >= 0)[~edge], hit[~edge])
    both = hit & (out[..., 0] >= 0) & ~edge
    assert both.sum() > 300
    np.testing.assert_allclose(out[..., 0][both], best[both], rtol=1e-5, atol=1e-4)
    assert np.array_equal(out[..., 2][both].astype(int), prim[both])
    assert np.all(out[..., 1][both] < 0)  # normals face the camera (-z)
    assert np.all(out[..., 3][both] == 1)  # entering


def test_sphere_misuse_names_the_fix():
    ctx = lucent.Context(backend=BACKEND)
    spheres = ctx.create_geometry_spheres()
    with pytest.raises(lucent.Error, match="float3"):
        spheres.centers = ctx.create_buffer("input", "float4", 2)
    scene, spheres = sphere_scene(ctx, radii=np.array([1, -1, 1], np.float32))
    ctx["scene"], ctx["image"] = scene, ctx.create_buffer("output", "float4", (4, 4))
    with pytest.raises(lucent.Error, match="at least 0"):
        ctx.launch(0, 4, 4)

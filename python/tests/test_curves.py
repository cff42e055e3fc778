"""Built-in curves from Python: a GeometryCurves of numpy control points, radii and segment
indices, hit programs written in a module string reading BuiltinCurveAttributes, the
answers checked against numpy's closed form for straight tubes, and misuse refused by
name."""
import numpy as np
import pytest

import lucent
from conftest import BACKEND

CURVE_MODULE = """
#include "lucent/device.h"
namespace py_curves {
LUCENT_MODULE(py_curves)
using namespace lucent;

struct Payload { float t; float u; unsigned prim; float ny; };
struct Camera { Handle scene; BufferView<float4> image; };
LUCENT_RECORD(Camera, scene, image)

// One ray per pixel along +z from the plane z = -5, x in [-0.5, 3.5] and y in [-1, 1].
LUCENT_RAY_GENERATION(camera, Camera) {
    const uint3 i = launch_index(), n = launch_size();
    const float x = (i.x + 0.5f) / n.x * 4 - 0.5f, y = ((i.y + 0.5f) / n.y * 2 - 1);
    Payload p{-1.0f, 0.0f, 0u, 0.0f};
    trace(rec.scene, make_ray(make_float3(x, y, -5), make_float3(0, 0, 1), 0, 0.0f), p);
    rec.image[make_uint2(i.x, i.y)] = make_float4(p.t, p.u, float(p.prim), p.ny);
}
LUCENT_CLOSEST_HIT(hit, NoRecord, Payload, BuiltinCurveAttributes) {
    prd.t = t_hit();
    prd.u = attr.u;
    prd.prim = primitive_index();
    prd.ny = attr.normal.y;
}
LUCENT_MISS(nothing, NoRecord, Payload) { prd.t = -1.0f; }
}
"""

# Three straight tubes of radius 0.4 along x (cubic B-splines of evenly spaced collinear
# points: segment k runs from x = k to x = k + 1 with u = x - k).
POINTS = np.array([[x, 0, 0] for x in range(-1, 5)], np.float32)
RADII = np.full(len(POINTS), 0.4, np.float32)
SEGMENTS = np.array([0, 1, 2], np.uint32)


def buffer(ctx, kind, values):
    b = ctx.create_buffer("input", kind, len(values))
    b.upload(values)
    return b


def curve_scene(ctx, radii=RADII, segments=SEGMENTS):
    ctx.add_module(CURVE_MODULE)
    ctx.set_ray_type(0, "probe", payload="py_curves::Payload")
    ctx.set_ray_generation_program(0, ctx.create_program("camera", "py_curves"))
    ctx.set_miss_program(0, ctx.create_program("nothing", "py_curves"))
    curves = ctx.create_geometry_curves()
    curves.curve_type = lucent.CURVE_CUBIC_BSPLINE
    curves.vertices = buffer(ctx, "float3", POINTS)
    curves.radii = buffer(ctx, "float", radii)
    curves.segment_indices = buffer(ctx, "uint", segments)
    material = ctx.create_material()
    material.set_closest_hit(0, ctx.create_program("hit", "py_curves"))
    instance = ctx.create_geometry_instance()
    instance.geometry = curves
    instance.add_material(material)
    scene = ctx.create_geometry_group()
    scene.add_child(instance)
    return scene, curves


def test_straight_curves_render_as_the_cylinder():
    ctx = lucent.Context(backend=BACKEND)
    scene, curves = curve_scene(ctx)
    assert curves.curve_type == lucent.CURVE_CUBIC_BSPLINE
    assert curves.primitive_count == 3
    size = (64, 32)
    image = ctx.create_buffer("output", "float4", size)
    ctx["scene"], ctx["image"] = scene, image
    ctx.launch(0, *size)
    out = image.download()
    w, h = size
    x = (np.arange(w) + 0.5) / w * 4 - 0.5
    y = (np.arange(h) + 0.5) / h * 2 - 1
    X, Y = np.meshgrid(x, y)
    # Inside the tube's side (not near the round ends at x = 0 and x = 3, nor the silhouette).
    side = (X > 0.02) & (X < 2.98) & (np.abs(Y) < 0.39)
    outside = np.abs(Y) > 0.41
    np.testing.assert_allclose(out[..., 0][side], 5 - np.sqrt(0.16 - Y[side] ** 2), atol=2e-5)
    np.testing.assert_allclose(out[..., 1][side], X[side] - np.floor(X[side]), atol=2e-4)
    assert np.array_equal(out[..., 2][side].astype(int), np.floor(X[side]).astype(int))
    np.testing.assert_allclose(out[..., 3][side], Y[side] / 0.4, atol=2e-4)
    assert np.all(out[..., 0][outside] < 0)


def test_curve_misuse_names_the_fix():
    ctx = lucent.Context(backend=BACKEND)
    curves = ctx.create_geometry_curves()
    with pytest.raises(lucent.Error, match="curve type 9"):
        curves.curve_type = 9
    with pytest.raises(lucent.Error, match="float3"):
        curves.vertices = ctx.create_buffer("input", "float4", 2)
    scene, _ = curve_scene(ctx, segments=np.array([0, 3], np.uint32))
    ctx["scene"], ctx["image"] = scene, ctx.create_buffer("output", "float4", (4, 4))
    with pytest.raises(lucent.Error, match="segment 1 starts at vertex 3"):
        ctx.launch(0, 4, 4)

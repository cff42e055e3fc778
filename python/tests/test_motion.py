"""Motion blur from Python: a matrix motion Transform and moving sphere centres set from
numpy, traced at given times by a module string that reads ray_time(), the answers checked
against the linear motion's closed form, and misuse refused by name."""
import numpy as np
import pytest

import lucent
from conftest import BACKEND

MOTION_MODULE = """
#include "lucent/device.h"
namespace py_motion {
LUCENT_MODULE(py_motion)
using namespace lucent;

struct Payload { float t; float time; };
struct Camera { Handle scene; BufferView<float4> rays; BufferView<float2> out; };
LUCENT_RECORD(Camera, scene, rays, out)

// Ray i: straight down -z from (x, 0, 5) at time w.
LUCENT_RAY_GENERATION(camera, Camera) {
    const unsigned i = launch_index().x;
    const float4 r = rec.rays[i];
    Payload p{-1.0f, -1.0f};
    trace(rec.scene, make_ray(make_float3(r.x, r.y, 5), make_float3(0, 0, -1), 0, 0.0f,
                              kInfinity, r.w), p);
    rec.out[i] = make_float2(p.t, p.time);
}
LUCENT_CLOSEST_HIT(hit, NoRecord, Payload, BuiltinSphereAttributes) {
    prd.t = t_hit();
    prd.time = ray_time();
}
LUCENT_MISS(nothing, NoRecord, Payload) { prd.t = -1.0f; prd.time = ray_time(); }
}
"""


def buffer_of(ctx, kind, values):
    b = ctx.create_buffer("input", kind, len(values))
    b.upload(np.asarray(values, np.float32))
    return b


def moving_scene(ctx):
    ctx.add_module(MOTION_MODULE)
    ctx.set_ray_type(0, "probe", payload="py_motion::Payload")
    ctx.set_ray_generation_program(0, ctx.create_program("camera", "py_motion"))
    ctx.set_miss_program(0, ctx.create_program("nothing", "py_motion"))
    spheres = ctx.create_geometry_spheres()
    spheres.set_motion_centers([buffer_of(ctx, "float3", [[0, 0, 0]]),
                                buffer_of(ctx, "float3", [[2, 0, 0]])])
    spheres.radii = buffer_of(ctx, "float", [0.5])
    material = ctx.create_material()
    material.set_closest_hit(0, ctx.create_program("hit", "py_motion"))
    instance = ctx.create_geometry_instance()
    instance.geometry = spheres
    instance.add_material(material)
    group = ctx.create_geometry_group()
    group.add_child(instance)
    transform = ctx.create_transform()
    transform.child = group
    keys = np.zeros((2, 3, 4), np.float32)
    keys[:, 0, 0] = keys[:, 1, 1] = keys[:, 2, 2] = 1
    keys[1, 1, 3] = 4  # y from 0 to 4
    transform.set_motion_matrices(keys, time_begin=0.0, time_end=1.0,
                                  flags=lucent.MOTION_FLAG_END_VANISH)
    return transform


def trace(ctx, scene, rays):
    rays = np.asarray(rays, np.float32)
    out = ctx.create_buffer("output", "float2", len(rays))
    ctx["scene"], ctx["rays"], ctx["out"] = scene, buffer_of(ctx, "float4", rays), out
    ctx.launch(0, len(rays))
    return out.download()


def test_moving_sphere_under_a_motion_transform_is_where_the_keys_say():
    ctx = lucent.Context(backend=BACKEND)
    scene = moving_scene(ctx)
    times = np.linspace(0, 1, 9, dtype=np.float32)
    # At time s the sphere is at (2 s, 4 s, 0): a ray over its centre hits at t = 4.5.
    rays = [[2 * s, 4 * s, 0, s] for s in times] + [[1, 2, 0, 0.0], [2, 4, 0, 1.5]]
    out = trace(ctx, scene, rays)
    np.testing.assert_allclose(out[:9, 0], 4.5, atol=1e-4)
    np.testing.assert_array_equal(out[:9, 1], times)
    assert out[9, 0] == -1  # at time 0 the sphere is at the origin
    assert out[10, 0] == -1 and out[10, 1] == 1.5  # vanished after the range


def test_motion_misuse_names_the_fix():
    ctx = lucent.Context(backend=BACKEND)
    transform = ctx.create_transform()
    with pytest.raises(lucent.Error, match="at least 2 keys"):
        transform.set_motion_matrices(np.zeros((1, 3, 4), np.float32))
    keys = np.tile(np.eye(3, 4, dtype=np.float32), (2, 1, 1))
    with pytest.raises(lucent.Error, match="time_begin < time_end"):
        transform.set_motion_matrices(keys, time_begin=1.0, time_end=0.0)
    with pytest.raises(ValueError, match="keys"):
        transform.set_motion_srt(np.zeros((2, 12), np.float32))

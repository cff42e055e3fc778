"""Ray flags, visibility masks and instance ids from Python: the node properties, the
constants, and a module (a C++ string) that traces with them."""
import numpy as np
import pytest

import lucent
from conftest import BACKEND

MODULE = """
#include "lucent/device.h"
namespace py_ray_control {
LUCENT_MODULE(py_ray_control, lucent::kUsesRayFlags)
using namespace lucent;

struct Payload { float depth; unsigned id; };

struct Camera { Handle scene; BufferView<float2> image; int mask; int flags; };
LUCENT_RECORD(Camera, scene, image, mask, flags)

// One ray down -z from z = 10 per launch index.
LUCENT_RAY_GENERATION(camera, Camera) {
    Payload p{-1.0f, 0u};
    trace(rec.scene, make_ray(make_float3(0, 0, 10), make_float3(0, 0, -1), 0, 0.0f), p,
          unsigned(rec.flags), unsigned(rec.mask));
    rec.image[launch_index().x] = make_float2(p.depth, float(p.id));
}

// Which copy was hit: the Transform's id, then the GeometryInstance's.
LUCENT_CLOSEST_HIT(depth, NoRecord, Payload, TriangleAttributes) {
    prd.depth = t_hit();
    prd.id = instance_id() * 100 + geometry_instance_id();
}

LUCENT_MISS(nothing, NoRecord, Payload) { prd.depth = -1.0f; prd.id = 0; }
}
"""


def scene(ctx):
    """One square (z = 0, wound counter-clockwise seen from +z) instanced twice: at z = 1
    (Transform id 1, mask 0x1) and z = -1 (id 2, mask 0x2)."""
    ctx.add_module(MODULE)
    ctx.set_ray_type(0, "probe", payload="py_ray_control::Payload")
    ctx.set_ray_generation_program(0, ctx.create_program("camera", "py_ray_control"))
    ctx.set_miss_program(0, ctx.create_program("nothing", "py_ray_control"))
    vertices = ctx.create_buffer("input", "float3", 4)
    vertices.upload(np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32))
    indices = ctx.create_buffer("input", "uint3", 2)
    indices.upload(np.array([[0, 1, 2], [0, 2, 3]], np.uint32))
    square = ctx.create_geometry_triangles()
    square.vertices, square.indices = vertices, indices
    material = ctx.create_material()
    material.set_closest_hit(0, ctx.create_program("depth", "py_ray_control"))
    instance = ctx.create_geometry_instance()
    instance.geometry = square
    instance.add_material(material)
    instance.instance_id = 5
    group = ctx.create_geometry_group()
    group.add_child(instance)
    top = ctx.create_group()
    for instance_id, z, mask in ((1, 1.0, 0x1), (2, -1.0, 0x2)):
        t = ctx.create_transform()
        t.matrix = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, z]], np.float32)
        t.child, t.instance_id, t.visibility_mask = group, instance_id, mask
        top.add_child(t)
    return top, instance


def cast(ctx, top, mask, flags=lucent.RAY_FLAG_NONE):
    image = ctx.create_buffer("output", "float2", 1)
    ctx["scene"], ctx["image"], ctx["mask"], ctx["flags"] = top, image, mask, flags
    ctx.launch(0, 1)
    return tuple(image.download()[0])


def test_masks_ids_and_flags_choose_what_a_ray_sees():
    ctx = lucent.Context(backend=BACKEND)
    top, instance = scene(ctx)
    assert cast(ctx, top, lucent.VISIBILITY_MASK_ALL) == (9.0, 105.0)
    assert cast(ctx, top, 0x2) == (11.0, 205.0)
    assert cast(ctx, top, 0x4) == (-1.0, 0.0)
    # The ray meets the squares' fronts: culling them leaves nothing.
    assert cast(ctx, top, 0xff, lucent.RAY_FLAG_CULL_FRONT_FACING_TRIANGLES) == (-1.0, 0.0)
    assert cast(ctx, top, 0xff, lucent.RAY_FLAG_CULL_BACK_FACING_TRIANGLES) == (9.0, 105.0)
    # The instance's mask applies below both Transforms: a ray needs a bit of each.
    instance.visibility_mask = 0x2
    assert cast(ctx, top, 0x1) == (-1.0, 0.0)
    assert cast(ctx, top, 0x3) == (9.0, 105.0)


def test_properties_round_trip_and_refuse_bad_values():
    ctx = lucent.Context(backend=BACKEND)
    group = ctx.create_geometry_group()
    assert group.visibility_mask == 0xFF
    group.visibility_mask = 0x10
    assert group.visibility_mask == 0x10
    with pytest.raises(lucent.Error, match="0x00..0xff"):
        group.visibility_mask = 0x100
    geometry = ctx.create_geometry_triangles()
    geometry.flags = lucent.GEOMETRY_FLAG_DISABLE_ANYHIT
    assert geometry.flags == lucent.GEOMETRY_FLAG_DISABLE_ANYHIT
    with pytest.raises(lucent.Error, match="kGeometryFlagDisableAnyHit"):
        geometry.flags = 4
    with pytest.raises(TypeError):
        ctx.create_transform().instance_id = -1

"""The engine from Python: a Context, buffers as numpy arrays, the node graph, variables and
a launch of the compiled modules' programs."""
import gc

import numpy as np
import pytest

import lucent
from conftest import BACKEND
from reference import Reference, random_mesh, random_rays


def test_version_and_modules():
    assert lucent.__version__.count(".") >= 1
    names = [m.name for m in lucent.modules()]
    for expected in ("lucent_mesh_queries", "first_program", "whitted", "igi"):
        assert expected in names
    queries = next(m for m in lucent.modules() if m.name == "lucent_mesh_queries")
    assert queries.uses_occluded
    assert {"closest_hits", "any_hits", "record_hit", "record_miss"} <= set(queries.programs)
    assert "ray generation closest_hits" in queries.describe()
    assert "float3" in lucent.types()


def test_buffers_round_trip():
    ctx = lucent.Context(backend=BACKEND)
    b = ctx.create_buffer("input", "float3", 5)
    assert (b.type, b.element, b.dimensionality, b.size, b.shape, len(b)) == (
        "input", "float3", 1, (5, 1, 1), (5, 3), 5)
    values = np.arange(15, dtype=np.float32).reshape(5, 3)
    b.upload(values)
    np.testing.assert_array_equal(b.download(), values)
    np.testing.assert_array_equal(np.asarray(b), values)
    image = ctx.create_buffer("output", "float4", (4, 3))
    assert image.shape == (3, 4, 4)
    grid = ctx.create_buffer("input_output", "uint", (2, 3, 4))
    assert grid.shape == (4, 3, 2) and grid.numpy().dtype == np.uint32
    m = ctx.create_buffer("input", "matrix4x3", 2)
    assert m.shape == (2, 3, 4)
    with pytest.raises(ValueError, match=r"upload of a \(4, 3\) float32 array; the buffer's shape is \(5, 3\)"):
        b.upload(values[:4])
    with pytest.raises(ValueError, match="no type 'float5'.*float3"):
        ctx.create_buffer("input", "float5", 4)
    with pytest.raises(ValueError, match="buffer type: expected 'input', 'output' or 'input_output'"):
        ctx.create_buffer("inout", "float", 4)


def test_views_are_zero_copy_and_guard_resizing():
    ctx = lucent.Context(backend=BACKEND)
    b = ctx.create_buffer("input", "float", 8)
    view = b.numpy()
    assert not view.flags.writeable
    with b.map() as writable:
        writable[:] = np.arange(8)
    assert view[3] == 3  # the same memory
    with pytest.raises(BufferError, match="2 numpy view"):
        b.resize(16)
    del view, writable
    gc.collect()
    b.resize(16)
    assert b.shape == (16,) and b.numpy().sum() == 0  # resizing zeroes


def test_variables_set_and_read():
    ctx = lucent.Context(backend=BACKEND)
    ctx["f"] = 1.5
    ctx["i"] = -3
    ctx["u"] = 2**31 + 5
    ctx["v3"] = (1.0, 2.0, 3.0)
    ctx["i2"] = np.array([1, 2], np.int32)
    ctx["f2"] = (1, 2)  # a tuple is a float vector
    ctx["u4"] = np.array([1, 2, 3, 4], np.uint32)
    ctx["m"] = np.arange(12, dtype=np.float64).reshape(3, 4)
    buf = ctx.create_buffer("input", "float", 3)
    ctx["b"] = buf
    group = ctx.create_geometry_group()
    ctx["scene"] = group
    assert ctx["f"] == 1.5 and ctx["i"] == -3 and ctx["u"] == 2**31 + 5
    assert ctx["v3"] == (1.0, 2.0, 3.0) and ctx["i2"] == (1, 2) and ctx["u4"] == (1, 2, 3, 4)
    assert ctx["f2"] == (1.0, 2.0) and isinstance(ctx["f2"][0], float)
    np.testing.assert_array_equal(ctx["m"], np.arange(12).reshape(3, 4))
    assert ctx["b"] is buf and ctx["scene"] is group
    assert "f" in ctx and sorted(ctx.variables())[:2] == ["b", "f"]
    del ctx["f"]
    assert "f" not in ctx
    with pytest.raises(KeyError, match="Context has no variable 'f'"):
        ctx["f"]
    with pytest.raises(TypeError, match=r"Context\['x'\].*\(2, 2\) float64"):
        ctx["x"] = np.zeros((2, 2))
    with pytest.raises(TypeError, match=r"Context\['x'\].*integer beyond 32 bits"):
        ctx["x"] = 2**40
    with pytest.raises(TypeError, match=r"Context\['x'\]"):
        ctx["x"] = object()
    material = ctx.create_material()
    material["color"] = (1, 0.5, 0.25)
    assert material["color"] == (1.0, 0.5, 0.25)


def build_query_scene(ctx, v, i):
    """The scene TriangleMesh builds, through the engine API."""
    ctx.add_module("lucent_mesh_queries")
    miss = ctx.create_program("record_miss")
    ctx.set_ray_type(0, "query", payload=miss)
    ctx.set_miss_program(0, miss)
    vertices = ctx.create_buffer("input", "float3", len(v))
    vertices.upload(v)
    indices = ctx.create_buffer("input", "uint3", len(i))
    indices.upload(i)
    triangles = ctx.create_geometry_triangles()
    triangles.vertices = vertices
    triangles.indices = indices
    material = ctx.create_material()
    material.set_closest_hit(0, ctx.create_program("record_hit"))
    instance = ctx.create_geometry_instance()
    instance.geometry = triangles
    instance.add_material(material)
    group = ctx.create_geometry_group()
    group.add_child(instance)
    ctx["mesh"] = group
    return group


def test_a_launch_of_the_query_module_matches_triangle_mesh(rng):
    """The query module launched through the engine answers as TriangleMesh does, bit for
    bit: on the CPU TriangleMesh calls the traversal directly (cpu_mesh_queries.cpp), so this
    holds the two paths to the same answers, rays that are not rays included."""
    v, i = random_mesh(rng)
    o, d = random_rays(rng, 2000)
    o[:20] = np.nan  # not rays: misses by definition
    d[20:40] = 0.0
    ctx = lucent.Context(backend=BACKEND)
    build_query_scene(ctx, v, i)
    ctx.entry_point_count = 2
    closest = ctx.create_program("closest_hits")
    any_hits = ctx.create_program("any_hits")
    ctx.set_ray_generation_program(0, closest)
    ctx.set_ray_generation_program(1, any_hits)
    for name, array, element in (("origins", o, "float3"), ("directions", d, "float3"),
                                 ("tmin", np.zeros(1, np.float32), "float"),
                                 ("tmax", np.full(1, np.inf, np.float32), "float")):
        b = ctx.create_buffer("input", element, len(array))
        b.upload(array)
        closest[name] = b
        any_hits[name] = b
    outputs = {name: ctx.create_buffer("output", element, len(o))
               for name, element in (("t", "float"), ("prim", "int"), ("uv", "float2"), ("normal", "float3"))}
    for name, b in outputs.items():
        closest[name] = b
    blocked = ctx.create_buffer("output", "uint8", len(o))
    any_hits["blocked"] = blocked
    ctx.validate()
    report = ctx.launch(0, len(o))
    assert report.exception_count == 0 and report.launch_ms > 0
    ctx.launch(1, len(o))
    prim = outputs["prim"].download()
    ref = Reference(v, i, o, d)
    np.testing.assert_array_equal(prim[ref.clear], ref.prim[ref.clear])
    assert (prim[:40] == -1).all()
    mesh = lucent.TriangleMesh(v, i, backend=BACKEND)
    mesh_hits = mesh.intersect(o, d)
    for name in ("t", "prim", "uv", "normal"):
        np.testing.assert_array_equal(outputs[name].download(), getattr(mesh_hits, name), err_msg=name)
    np.testing.assert_array_equal(blocked.download() == 1, mesh.occluded(o, d))
    # New contents recompile nothing: a second launch on moved rays.
    with closest["origins"].map() as a:
        a += np.float32(0.0)
    assert not ctx.launch(0, len(o)).recompiled


def first_program_scene(ctx, width, height):
    """docs/programming-model.md's first program, its host side written in Python: one
    triangle before the camera; returns the output image buffer (width x height float3)."""
    camera = ctx.create_program("camera", module="first_program")
    ctx.set_ray_type(0, "radiance", payload="first_program::Payload")
    ctx.set_ray_generation_program(0, camera)
    ctx.set_miss_program(0, ctx.create_program("background"))
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
    image = ctx.create_buffer("output", "float3", (width, height))
    ctx["eye"] = (0, 0, 0)
    ctx["scene"] = scene
    ctx["image"] = image
    return image


def test_the_first_program_from_python():
    """docs/programming-model.md's first program, its host side written in Python."""
    ctx = lucent.Context(backend=BACKEND)
    image = first_program_scene(ctx, 64, 48)
    ctx.launch(0, 64, 48)
    pixels = image.numpy()
    assert pixels.shape == (48, 64, 3)
    lit = pixels[..., 0] > 0.2
    assert 200 < lit.sum() < 64 * 48 - 200
    np.testing.assert_allclose(pixels[0, 0], (0.1, 0.1, 0.2), rtol=1e-6)  # the background


def test_moving_a_context_to_other_devices_keeps_its_scene_and_results():
    """ctx.devices: the list launches run on; setting it moves later launches (and what the
    last launch wrote stays readable), a list that cannot run changes nothing."""
    ctx = lucent.Context(backend=BACKEND)
    start = ctx.devices
    assert start == (["cuda:0"] if BACKEND == "cuda" else ["cpu"])
    image = first_program_scene(ctx, 32, 24)
    ctx.launch(0, 32, 24)
    reference = image.numpy().copy()  # read on the device that launched
    assert (reference[..., 0] > 0.2).sum() > 50
    image.upload(np.zeros((24, 32, 3), np.float32))
    ctx.launch(0, 32, 24)
    ctx.devices = ["cpu", "cpu"]  # before the image is read: it must survive the move
    np.testing.assert_array_equal(image.numpy(), reference)
    assert ctx.devices == ["cpu", "cpu"] and ctx.device_count == 2
    image.upload(np.zeros((24, 32, 3), np.float32))
    assert ctx.launch(0, 32, 24).recompiled  # compiled again for the new devices
    # The CPU rounds what a GPU computes with fused multiply-adds differently.
    np.testing.assert_allclose(image.numpy(), reference, rtol=1e-5, atol=1e-6)
    with pytest.raises(lucent.Error, match="cuda:999"):
        ctx.devices = "cpu,999"
    with pytest.raises(lucent.Error, match="neither a GPU number nor cpu"):
        ctx.devices = "cpu,gpu"
    assert ctx.devices == ["cpu", "cpu"]
    ctx.devices = None  # back to the backend's one device
    assert ctx.devices == start and ctx.device_count == 1
    ctx.launch(0, 32, 24)
    np.testing.assert_array_equal(image.numpy(), reference)


def test_engine_errors_are_lucent_errors():
    ctx = lucent.Context(backend=BACKEND)
    with pytest.raises(lucent.Error, match="no_such_module"):
        ctx.add_module("no_such_module")
    ctx.add_module("first_program")
    with pytest.raises(lucent.Error, match="no_such_program"):
        ctx.create_program("no_such_program")
    with pytest.raises(ValueError, match="set_ray_type: payload: no type 'NoSuchPayload'"):
        ctx.set_ray_type(0, "r", payload="NoSuchPayload")
    with pytest.raises(lucent.Error):
        ctx.launch(0, 4)  # nothing is bound
    assert issubclass(lucent.Error, RuntimeError)


def test_node_graph_objects():
    ctx = lucent.Context(backend=BACKEND)
    group = ctx.create_group()
    transform = ctx.create_transform()
    gg = ctx.create_geometry_group()
    transform.child = gg
    transform.matrix = np.eye(4)
    np.testing.assert_array_equal(transform.matrix, np.eye(4)[:3])
    assert group.add_child(transform) == 0 and group.child_count == 1
    assert group.children[0] is transform and transform.child is gg
    assert (group.kind, transform.kind, gg.kind) == ("Group", "Transform", "GeometryGroup")
    assert ctx.create_acceleration().builder == "auto"
    assert ctx.create_acceleration("sah").builder == "sah"
    group.acceleration = ctx.create_acceleration("none")
    assert group.acceleration.builder == "none"
    gg.acceleration.refit = True
    assert gg.acceleration.refit
    with pytest.raises(ValueError, match="builder: expected 'auto', 'sah', 'none' or 'gpu_hploc'"):
        ctx.create_acceleration("lbvh")
    geometry = ctx.create_geometry()
    geometry.primitive_count = 3
    geometry["radius"] = 0.5
    assert geometry.primitive_count == 3 and geometry["radius"] == 0.5

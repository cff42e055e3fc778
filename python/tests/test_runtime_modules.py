"""Programs written in Python strings: Context.add_module with a module's C++ text, compiled
at run time by the system's C++ compiler for the host (and by NVRTC for the GPU), then used
like a compiled-in module."""
import numpy as np
import pytest

import lucent
from conftest import BACKEND

# A depth-and-normal camera: one ray per pixel down -z; the closest hit writes the hit
# distance and the geometric normal's z, a miss writes (-1, 0).
DEPTH_MODULE = """
#include "lucent/device.h"
namespace {name} {{
LUCENT_MODULE({name})
using namespace lucent;

struct Payload {{ float depth; float facing; }};

struct Camera {{ Handle scene; BufferView<float2> image; float height; }};
LUCENT_RECORD(Camera, scene, image, height)

LUCENT_RAY_GENERATION(camera, Camera) {{
    const uint3 i = launch_index(), n = launch_size();
    const float x = (i.x + 0.5f) / n.x * 2 - 1, y = 1 - (i.y + 0.5f) / n.y * 2;
    Payload p{{-1.0f, 0.0f}};
    trace(rec.scene, make_ray(make_float3(x, y, rec.height), make_float3(0, 0, -1), 0, 0.0f), p);
    rec.image[make_uint2(i.x, i.y)] = make_float2(p.depth, p.facing);
}}

LUCENT_CLOSEST_HIT(depth, NoRecord, Payload, TriangleAttributes) {{
    prd.depth = t_hit();
    prd.facing = fabsf(normalize(attr.geometric_normal).z);
}}

LUCENT_MISS(nothing, NoRecord, Payload) {{ prd.depth = -1.0f; prd.facing = 0.0f; }}
}}
"""


def depth_image(ctx, module_name, size=(8, 4), height=2.0, payload=None, camera="camera"):
    """Launches the depth camera (ray-generation program `camera`; the payload type
    `payload`, else the module's Payload) over a square at z = 0 covering x, y in
    [-0.5, 0.5] (no pixel centre lies on its edges)."""
    ctx.set_ray_type(0, "probe", payload=payload or f"{module_name}::Payload")
    ctx.set_ray_generation_program(0, ctx.create_program(camera, module_name))
    ctx.set_miss_program(0, ctx.create_program("nothing", module_name))
    vertices = ctx.create_buffer("input", "float3", 4)
    vertices.upload(np.array([[-.5, -.5, 0], [.5, -.5, 0], [.5, .5, 0], [-.5, .5, 0]], np.float32))
    indices = ctx.create_buffer("input", "uint3", 2)
    indices.upload(np.array([[0, 1, 2], [0, 2, 3]], np.uint32))
    square = ctx.create_geometry_triangles()
    square.vertices, square.indices = vertices, indices
    material = ctx.create_material()
    material.set_closest_hit(0, ctx.create_program("depth", module_name))
    instance = ctx.create_geometry_instance()
    instance.geometry = square
    instance.add_material(material)
    scene = ctx.create_geometry_group()
    scene.add_child(instance)
    image = ctx.create_buffer("output", "float2", size)
    ctx["scene"], ctx["image"], ctx["height"] = scene, image, height
    ctx.launch(0, *size)
    return image.download()


def expected_depth(size=(8, 4), height=2.0):
    w, h = size
    x = (np.arange(w) + 0.5) / w * 2 - 1
    y = 1 - (np.arange(h) + 0.5) / h * 2
    inside = (np.abs(x)[None, :] < 0.5) & (np.abs(y)[:, None] < 0.5)
    depth = np.where(inside, height, -1.0)
    return np.stack([depth, inside.astype(float)], axis=-1).astype(np.float32)


def test_a_module_from_a_string_renders_like_a_compiled_one():
    ctx = lucent.Context(backend=BACKEND)
    module = ctx.add_module(DEPTH_MODULE.format(name="py_depth"))
    assert module.name == "py_depth"
    assert {"camera", "depth", "nothing"} <= set(module.programs)
    assert "py_depth" in [m.name for m in lucent.modules()]
    assert "py_depth::Payload" in lucent.types()
    np.testing.assert_allclose(depth_image(ctx, "py_depth"), expected_depth(), rtol=1e-6)
    # A second context gets the loaded module back, without compiling it again.
    again = lucent.Context(backend=BACKEND)
    assert again.add_module(DEPTH_MODULE.format(name="py_depth")).name == "py_depth"
    np.testing.assert_allclose(depth_image(again, "py_depth", height=3.0),
                               expected_depth(height=3.0), rtol=1e-6)


def test_a_module_from_a_file(tmp_path):
    header = tmp_path / "file_depth.h"
    header.write_text(DEPTH_MODULE.format(name="py_file_depth"))
    ctx = lucent.Context(backend=BACKEND)
    assert ctx.add_module(file=str(header)).name == "py_file_depth"
    np.testing.assert_allclose(depth_image(ctx, "py_file_depth"), expected_depth(), rtol=1e-6)


def test_compile_errors_name_the_file_and_line():
    broken = DEPTH_MODULE.format(name="py_broken").replace(
        "struct Payload", "not_a_type oops;\nstruct Payload", 1)
    line = broken.split("\n").index("not_a_type oops;") + 1
    ctx = lucent.Context(backend=BACKEND)
    with pytest.raises(lucent.Error, match=rf"(?s)could not compile module 'py_broken'.*"
                                           rf"broken\.h:{line}.*not_a_type"):
        ctx.add_module(broken, name="broken.h")
    assert "py_broken" not in [m.name for m in lucent.modules()]


def test_bad_arguments_say_what_to_give():
    ctx = lucent.Context(backend=BACKEND)
    with pytest.raises(ValueError, match="a module's name .*C\\+\\+ text, or file="):
        ctx.add_module()
    with pytest.raises(ValueError, match="not both"):
        ctx.add_module("first_program", file="x.h")
    with pytest.raises(lucent.Error, match="no module named 'no_such_module'"):
        ctx.add_module("no_such_module")
    with pytest.raises(lucent.Error, match="declares no module.*LUCENT_MODULE"):
        ctx.add_module("int x;\nint y;\n")
    with pytest.raises(lucent.Error, match="cannot read the module file .*absent.h"):
        ctx.add_module(file="/nonexistent/absent.h")


def test_another_text_under_a_loaded_name_is_refused():
    lucent.Context(backend=BACKEND).add_module(DEPTH_MODULE.format(name="py_twice"))
    changed = DEPTH_MODULE.format(name="py_twice").replace("prd.depth = -1.0f", "prd.depth = -2.0f")
    # In another context too: the process holds one text per module name.
    with pytest.raises(lucent.Error, match="(?s)different text.*another LUCENT_MODULE name"):
        lucent.Context(backend=BACKEND).add_module(changed)


@pytest.mark.skipif(not lucent.cuda_built, reason="built without the CUDA backend")
def test_a_module_from_a_string_compiles_into_the_megakernel_for_sm_90():
    try:
        ctx = lucent.Context(backend="cpu", jit_check_sm=90)
    except lucent.Error as e:
        pytest.skip(f"no NVRTC here: {e}")
    ctx.add_module(DEPTH_MODULE.format(name="py_jit_depth"))
    np.testing.assert_allclose(depth_image(ctx, "py_jit_depth"), expected_depth(), rtol=1e-6)


def first_program_image(ctx, module):
    """The first program of docs/programming-model.md, from `module`, at 64x48."""
    ctx.set_ray_type(0, "radiance", payload=f"{module}::Payload")
    ctx.set_ray_generation_program(0, ctx.create_program("camera", module))
    ctx.set_miss_program(0, ctx.create_program("background", module))
    vertices = ctx.create_buffer("input", "float3", 3)
    vertices.upload(np.array([[-1, -1, -2], [1, -1, -2.5], [0, 1, -1.5]], np.float32))
    triangle = ctx.create_geometry_triangles()
    triangle.vertices = vertices
    material = ctx.create_material()
    material.set_closest_hit(0, ctx.create_program("shade", module))
    material["color"] = (1, 0.5, 0.2)
    instance = ctx.create_geometry_instance()
    instance.geometry = triangle
    instance.add_material(material)
    scene = ctx.create_geometry_group()
    scene.add_child(instance)
    image = ctx.create_buffer("output", "float3", (64, 48))
    ctx["eye"], ctx["scene"], ctx["image"] = (0, 0, 0), scene, image
    ctx.launch(0, 64, 48)
    return image.download()


def test_a_compiled_in_module_and_its_text_compiled_at_run_time_give_the_same_image():
    from conftest import REPO
    text = (REPO / "examples" / "first-program" / "first_program.h").read_text()
    renamed = text.replace("first_program", "first_program_at_run_time")
    compiled_in = first_program_image(lucent.Context(backend=BACKEND), "first_program")
    ctx = lucent.Context(backend=BACKEND)
    ctx.add_module(renamed, name="first_program_at_run_time.h")
    at_run_time = first_program_image(ctx, "first_program_at_run_time")
    assert np.count_nonzero(compiled_in[..., 0] > 0.2) > 100  # the triangle is there
    np.testing.assert_array_equal(at_run_time, compiled_in)


# The depth camera with its rays deferred (trace_deferred): the payload is the image's own
# element, which the closest-hit or miss program writes after the camera has returned.
DEFERRED_DEPTH_MODULE = """
#include "lucent/device.h"
namespace {name} {{
LUCENT_MODULE({name})
using namespace lucent;

struct Camera {{ Handle scene; BufferView<float2> image; float height; }};
LUCENT_RECORD(Camera, scene, image, height)

LUCENT_RAY_GENERATION(camera, Camera) {{
    const uint3 i = launch_index(), n = launch_size();
    const float x = (i.x + 0.5f) / n.x * 2 - 1, y = 1 - (i.y + 0.5f) / n.y * 2;
    trace_deferred(rec.scene, make_ray(make_float3(x, y, rec.height), make_float3(0, 0, -1), 0, 0.0f),
                   rec.image[make_uint2(i.x, i.y)]);
}}

LUCENT_RAY_GENERATION(camera_into_local, Camera) {{
    float2 p = make_float2(-1.0f, 0.0f);
    trace_deferred(rec.scene, make_ray(make_float3(0, 0, rec.height), make_float3(0, 0, -1), 0, 0.0f), p);
    rec.image[make_uint2(launch_index().x, launch_index().y)] = p;
}}

LUCENT_CLOSEST_HIT(depth, NoRecord, float2, TriangleAttributes) {{
    prd = make_float2(t_hit(), fabsf(normalize(attr.geometric_normal).z));
}}

LUCENT_MISS(nothing, NoRecord, float2) {{ prd = make_float2(-1.0f, 0.0f); }}
}}
"""


def test_a_module_from_a_string_may_defer_its_rays():
    ctx = lucent.Context(backend=BACKEND)
    ctx.add_module(DEFERRED_DEPTH_MODULE.format(name="py_deferred_depth"))
    size = (40, 32)  # no pixel centre on the square's edges
    np.testing.assert_allclose(depth_image(ctx, "py_deferred_depth", size=size, payload="float2"),
                               expected_depth(size=size), rtol=1e-6)


@pytest.mark.skipif(BACKEND != "cpu", reason="the GPU traces a deferred ray at once")
def test_a_deferred_ray_into_a_local_is_refused():
    ctx = lucent.Context(backend=BACKEND)
    ctx.add_module(DEFERRED_DEPTH_MODULE.format(name="py_deferred_local"))
    with pytest.raises(lucent.Error, match="trace_deferred.*local variable.*buffer"):
        depth_image(ctx, "py_deferred_local", payload="float2", camera="camera_into_local")

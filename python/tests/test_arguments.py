"""Every bad argument is a Python exception that names the argument, and the shape and
dtype expected; never a crash."""
import numpy as np
import pytest

import lucent
from conftest import BACKEND

V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], np.float32)
I = np.array([[0, 1, 2], [1, 3, 2]], np.uint32)
O = np.array([[0.2, 0.2, 1], [0.7, 0.7, 1]], np.float32)
D = np.array([[0, 0, -1], [0, 0, -1]], np.float32)


@pytest.fixture(scope="module")
def mesh():
    return lucent.TriangleMesh(V, I, backend=BACKEND)


@pytest.mark.parametrize("vertices, error, words", [
    (V.astype(np.float16), TypeError, ["vertices", "(N, 3) float32", "float16"]),
    (V.astype(np.int32), TypeError, ["vertices", "float32", "int32", "astype"]),
    (V[:, :2].copy(), ValueError, ["vertices", "(N, 3) float32", "(4, 2) float32"]),
    (V.ravel(), ValueError, ["vertices", "(N, 3)", "(12,) float32"]),
    (np.asfortranarray(np.tile(V, (1, 1)))[::2], ValueError, ["vertices", "non-contiguous"]),
    (np.zeros((0, 3), np.float32), ValueError, ["vertices", "empty"]),
    ("not an array", TypeError, ["vertices", "(N, 3) float32", "str"]),
    (np.array([["a", "b", "c"]] * 4), TypeError, ["vertices", "float32"]),
])
def test_bad_vertices(vertices, error, words):
    with pytest.raises(error) as e:
        lucent.TriangleMesh(vertices, I, backend=BACKEND)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


@pytest.mark.parametrize("indices, error, words", [
    (I.astype(np.float32), TypeError, ["indices", "(M, 3) uint32", "float32"]),
    (I[:, :2].copy(), ValueError, ["indices", "(M, 3) uint32", "(2, 2) uint32"]),
    (np.array([[0, 1, 4]], np.uint32), ValueError, ["indices[0, 2] = 4", "out of range", "[0, 4)"]),
    (np.array([[0, 1, 2], [0, -1, 2]], np.int64), ValueError, ["indices[1, 1] = -1", "out of range"]),
    (np.array([[0, 1, 2**32 + 1]], np.int64), ValueError, ["indices[0, 2] = 4294967297", "out of range"]),
    (np.zeros((0, 3), np.uint32), ValueError, ["indices", "empty"]),
    (np.ascontiguousarray(np.tile(I, (1, 2)))[:, ::2], ValueError, ["indices", "non-contiguous"]),
])
def test_bad_indices(indices, error, words):
    with pytest.raises(error) as e:
        lucent.TriangleMesh(V, indices, backend=BACKEND)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_converted_inputs_give_the_same_answers(mesh):
    other = lucent.TriangleMesh(V.astype(np.float64), I.astype(np.int64), backend=BACKEND)
    a, b = mesh.intersect(O, D), other.intersect(O.astype(np.float64), D.tolist())
    np.testing.assert_array_equal(a.prim, b.prim)
    np.testing.assert_array_equal(a.t, b.t)
    assert list(a.prim) == [0, 1]


def test_bad_backend():
    with pytest.raises(ValueError, match="backend: expected 'auto', 'cpu' or 'cuda'; got 'gpu'"):
        lucent.TriangleMesh(V, I, backend="gpu")
    with pytest.raises(ValueError, match="Context: backend"):
        lucent.Context(backend="CPU")
    with pytest.raises(ValueError, match="render: backend"):
        lucent.render("whitted", backend="vulkan")


@pytest.mark.parametrize("option, values", [
    ("register_variants", ("background", "with_kernel", "off")),
    ("tree_upgrades", ("background", "with_build", "off")),
])
def test_context_choices(option, values):
    for value in values:
        lucent.Context(backend="cpu", **{option: value})
    first, second, third = values
    with pytest.raises(ValueError, match=f"{option}: expected '{first}', '{second}' or "
                                         f"'{third}'; got 'sync'"):
        lucent.Context(backend="cpu", **{option: "sync"})


@pytest.mark.parametrize("origins, directions, error, words", [
    (O.astype(np.int64), D, TypeError, ["intersect", "origins", "(R, 3) float32", "int64"]),
    (O, D.astype(np.float16), TypeError, ["directions", "float16"]),
    (O[:, :2].copy(), D, ValueError, ["origins", "(R, 3) float32", "(2, 2) float32"]),
    (O, D[:1], ValueError, ["directions must be (2, 3) like origins", "(1, 3) float32"]),
    (np.tile(O, (1, 2))[:, ::2], D, ValueError, ["origins", "non-contiguous", "np.ascontiguousarray(origins)"]),
    (O, np.asfortranarray(np.tile(D, (2, 1))), ValueError, ["directions", "(4, 3)"]),
    (None, D, TypeError, ["origins", "NoneType"]),
    (O.reshape(2, 3, 1), D, ValueError, ["origins", "(2, 3, 1) float32"]),
])
def test_bad_rays(mesh, origins, directions, error, words):
    for call in (mesh.intersect, mesh.occluded):
        with pytest.raises(error) as e:
            call(origins, directions)
        for w in words:
            assert w in str(e.value).replace("occluded", "intersect"), (w, str(e.value))


@pytest.mark.parametrize("tmin, tmax, error, words", [
    (np.zeros(3, np.float32), np.inf, ValueError, ["tmin has 3 values for 2 rays"]),
    (0.0, np.ones((2, 1), np.float32), ValueError, ["tmax", "(R,) float32", "(2, 1) float32"]),
    (0.0, np.ones(2, np.int32), TypeError, ["tmax", "int32"]),
    ("0", np.inf, TypeError, ["tmin", "str"]),
    (True, np.inf, TypeError, ["tmin", "bool"]),
])
def test_bad_intervals(mesh, tmin, tmax, error, words):
    with pytest.raises(error) as e:
        mesh.intersect(O, D, tmin=tmin, tmax=tmax)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_numpy_scalars_as_intervals(mesh):
    hits = mesh.intersect(O, D, tmin=np.float32(0.5), tmax=np.array(2.0))
    assert list(hits.prim) == [0, 1]
    assert list(mesh.intersect(O, D, tmax=np.float64(0.5)).prim) == [-1, -1]


def test_bad_updates(mesh):
    with pytest.raises(ValueError, match=r"update: vertices must be \(4, 3\).*\(3, 3\) float32"):
        mesh.update(V[:3].copy())
    with pytest.raises(TypeError, match="update: vertices.*int8"):
        mesh.update(V.astype(np.int8))
    with pytest.raises(ValueError, match="non-contiguous"):
        mesh.update(np.tile(V, (2, 1))[::2])
    assert list(mesh.intersect(O, D).prim) == [0, 1]  # the mesh is unchanged


def test_bad_load_and_render_arguments(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2 3\n")
    with pytest.raises(lucent.Error, match="bad.obj"):
        lucent.TriangleMesh.load(str(bad))
    with pytest.raises(ValueError, match="render: .*no-such-sample"):
        lucent.render("no-such-sample")
    with pytest.raises(ValueError, match="render: .*colour"):
        lucent.render("whitted", size=(8, 8), colour=3)
    with pytest.raises(ValueError, match=r"size must be \(width, height\)"):
        lucent.render("whitted", size=(0, 8))

"""TriangleMesh.intersect / occluded / update / load against the numpy reference."""
import numpy as np
import pytest

import lucent
from conftest import BACKEND
from reference import Reference, random_mesh, random_rays


def check_hits(hits, ref, min_clear=0.97):
    """Every ray whose answer rounding cannot change must match the reference exactly in
    prim and to 1e-5 relative in t; and nearly all rays must be such rays."""
    clear = ref.clear
    assert clear.mean() >= min_clear, f"only {clear.mean():.3f} of the rays are clear cases"
    np.testing.assert_array_equal(hits.prim[clear], ref.prim[clear])
    hit = clear & (ref.prim >= 0)
    miss = clear & (ref.prim < 0)
    assert hit.sum() > 50 and miss.sum() > 20, "the rays must both hit and miss"
    np.testing.assert_allclose(hits.t[hit], ref.t[hit], rtol=1e-5)
    np.testing.assert_allclose(hits.uv[hit], ref.uv[hit], atol=1e-4)
    np.testing.assert_allclose(hits.normal[hit], ref.normal[hit], atol=1e-5)
    assert np.all(np.isinf(hits.t[miss])) and np.all(hits.t[miss] > 0)
    assert np.all(hits.uv[miss] == 0) and np.all(hits.normal[miss] == 0)
    # The rays rounding may decide still answer sensibly: a real triangle at a t > 0.
    assert np.all((hits.prim >= -1) & (hits.prim < ref.triangle_count))
    assert np.all(hits.t[hits.prim >= 0] > 0) and np.all(np.isinf(hits.t[hits.prim < 0]))
    assert hits.t.dtype == np.float32 and hits.prim.dtype == np.int32
    assert hits.uv.shape == (len(ref.t), 2) and hits.normal.shape == (len(ref.t), 3)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_intersect_matches_the_reference(seed):
    rng = np.random.default_rng(seed)
    v, i = random_mesh(rng)
    o, d = random_rays(rng, 3000)
    mesh = lucent.TriangleMesh(v, i, backend=BACKEND)
    hits = mesh.intersect(o, d)
    check_hits(hits, Reference(v, i, o, d))
    assert len(hits) == 3000 and hits.hit.sum() == (hits.prim >= 0).sum()


def test_intervals_per_ray_and_for_all(rng):
    v, i = random_mesh(rng)
    o, d = random_rays(rng, 3000)
    mesh = lucent.TriangleMesh(v, i, backend=BACKEND)
    tmin = rng.uniform(0, 0.5, 3000).astype(np.float32)
    tmax = rng.uniform(0.3, 1.5, 3000)  # float64: converted
    check_hits(mesh.intersect(o, d, tmin=tmin, tmax=tmax), Reference(v, i, o, d, tmin, tmax))
    check_hits(mesh.intersect(o, d, tmin=0.25, tmax=0.9), Reference(v, i, o, d, 0.25, 0.9))
    # The same mesh again with one bound for all rays: the buffers change size back.
    check_hits(mesh.intersect(o, d), Reference(v, i, o, d))


def test_occluded_matches_the_reference(rng):
    v, i = random_mesh(rng)
    o, d = random_rays(rng, 3000)
    mesh = lucent.TriangleMesh(v, i, backend=BACKEND)
    tmax = rng.uniform(0.1, 2.0, 3000).astype(np.float32)
    ref = Reference(v, i, o, d, 0.0, tmax)
    blocked = mesh.occluded(o, d, tmax)
    assert blocked.dtype == np.bool_ and blocked.shape == (3000,)
    assert ref.clear.mean() > 0.97
    np.testing.assert_array_equal(blocked[ref.clear], ref.blocked[ref.clear])
    assert 100 < blocked.sum() < 2900
    # Unbounded: occluded exactly where intersect hits (on clear rays).
    full = Reference(v, i, o, d)
    np.testing.assert_array_equal(mesh.occluded(o, d)[full.clear], full.blocked[full.clear])


def test_rays_that_are_not_rays_miss(rng):
    v, i = random_mesh(rng)
    mesh = lucent.TriangleMesh(v, i, backend=BACKEND)
    nan, inf = np.float32(np.nan), np.float32(np.inf)
    o = np.array([[nan, 0, 0], [0, 0, 3], [inf, 0, 0], [0, 0, 3], [0, 0, 3], [0, 0, 3]], np.float32)
    d = np.array([[0, 0, -1], [0, nan, -1], [0, 0, -1], [0, 0, 0], [0, 0, -1], [0, 0, -1]], np.float32)
    tmin = np.array([0, 0, 0, 0, nan, 0], np.float32)
    tmax = np.array([inf, inf, inf, inf, inf, nan], np.float32)
    hits = mesh.intersect(o, d, tmin, tmax)
    assert np.all(hits.prim == -1) and np.all(np.isinf(hits.t))
    assert not mesh.occluded(o, d, tmax, tmin).any()
    # The same ray with proper values does hit the mesh (through the cube's middle).
    good = mesh.intersect(np.array([[0, 0, 3]], np.float32), np.array([[0, 0, -1]], np.float32))
    assert good.prim[0] >= 0


def test_empty_batches_give_empty_answers(rng):
    v, i = random_mesh(rng)
    mesh = lucent.TriangleMesh(v, i, backend=BACKEND)
    empty = np.zeros((0, 3), np.float32)
    hits = mesh.intersect(empty, empty)
    assert hits.t.shape == (0,) and hits.prim.shape == (0,) and hits.uv.shape == (0, 2)
    assert mesh.occluded(empty, empty, np.zeros(0, np.float32)).shape == (0,)


def test_batches_of_changing_size(rng):
    v, i = random_mesh(rng)
    mesh = lucent.TriangleMesh(v, i, backend=BACKEND)
    for count in (1000, 10, 1, 2500, 7):
        o, d = random_rays(rng, count)
        hits = mesh.intersect(o, d)
        ref = Reference(v, i, o, d)
        np.testing.assert_array_equal(hits.prim[ref.clear], ref.prim[ref.clear])


def test_update_refits_and_rebuilds(rng):
    v, i = random_mesh(rng)
    o, d = random_rays(rng, 3000)
    mesh = lucent.TriangleMesh(v, i, backend=BACKEND)
    mesh.intersect(o, d)
    moved = (v * np.float32(0.7) + rng.uniform(-0.2, 0.2, (1, 3))).astype(np.float32)
    mesh.update(moved)
    check_hits(mesh.intersect(o, d), Reference(moved, i, o, d))
    shuffled = rng.permutation(v).astype(np.float32)
    mesh.update(shuffled, rebuild=True)
    check_hits(mesh.intersect(o, d), Reference(shuffled, i, o, d))
    mesh.update(shuffled.astype(np.float64))  # converted
    check_hits(mesh.intersect(o, d), Reference(shuffled, i, o, d))


def test_load_obj_and_a_builtin_scene(tmp_path, rng):
    v, i = random_mesh(rng, 50, 60)
    path = tmp_path / "mesh.obj"
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in v] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in i]
    path.write_text("\n".join(lines) + "\n")
    mesh = lucent.TriangleMesh.load(str(path), backend=BACKEND)
    assert (mesh.vertex_count, mesh.triangle_count) == (50, 60)
    o, d = random_rays(rng, 2000)
    check_hits(mesh.intersect(o, d), Reference(v, i, o, d), min_clear=0.95)
    cornell = lucent.TriangleMesh.load("cornell", backend=BACKEND)
    assert cornell.triangle_count > 10
    # From inside the box (open at the front) most rays hit a wall.
    dirs = rng.normal(size=(500, 3)).astype(np.float32)
    inside = np.tile(np.array([[278, 274, 280]], np.float32), (500, 1))
    hits = cornell.intersect(inside, dirs)
    assert (hits.prim >= 0).mean() > 0.6 and np.all(hits.t[hits.prim >= 0] > 0)
    with pytest.raises(lucent.Error, match="missing.obj"):
        lucent.TriangleMesh.load(str(tmp_path / "missing.obj"))


def test_threads_share_a_mesh(rng):
    import threading

    v, i = random_mesh(rng)
    o, d = random_rays(rng, 2000)
    mesh = lucent.TriangleMesh(v, i, backend=BACKEND)
    expected = mesh.intersect(o, d).prim
    results = [None] * 4

    def run(k):
        results[k] = mesh.intersect(o, d).prim if k % 2 == 0 else mesh.occluded(o, d)

    threads = [threading.Thread(target=run, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    np.testing.assert_array_equal(results[0], expected)
    np.testing.assert_array_equal(results[2], expected)
    np.testing.assert_array_equal(results[1], expected >= 0)


def test_the_gpu_megakernel_of_the_query_module_compiles_for_sm_90(rng):
    if not lucent.cuda_built:
        pytest.skip("this build has no CUDA backend")
    v, i = random_mesh(rng, 30, 20)
    o, d = random_rays(rng, 100)
    mesh = lucent.TriangleMesh(v, i, backend="cpu", jit_check_sm=90)
    ref = Reference(v, i, o, d)
    hits = mesh.intersect(o, d)  # generates and compiles the megakernel for sm_90 with NVRTC
    report = mesh.last_launch
    assert report.jit_ms > 0 or report.jit_cached
    # The CPU backend has no launch shapes to try and no kernel variants.
    assert report.launch_shape_trial is False and report.registers_capped is False
    assert report.register_cap == 0
    assert report.trace_inlined is False
    assert report.lanes_refilled is False
    assert report.trees_upgraded == 0  # the CPU builds its tree with spatial splits at once
    np.testing.assert_array_equal(hits.prim[ref.clear], ref.prim[ref.clear])
    mesh.occluded(o, d)  # the occlusion entry is in the same megakernel

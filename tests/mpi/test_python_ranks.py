"""The Python module across ranks: ctest runs this file as mpi.python, with pytest on every
rank of `mpirun --allow-run-as-root --oversubscribe -np 3 /usr/bin/python3 -m pytest ...`
(python/CMakeLists.txt). Every rank runs every test in the same order, as an SPMD program
does, and renders each sample across the ranks and alone: the bytes must be equal on every
rank (every rank's outputs hold the whole image). The one-process side of the same API is
python/tests/test_ranks.py."""
import numpy as np
import pytest

import lucent

SIZE = (64, 48)


@pytest.fixture(scope="module")
def world():
    ranks = lucent.Ranks.world()  # collective: every rank makes it here
    assert ranks.size == 3, "mpi.python runs under mpirun -np 3"
    return ranks


def test_every_rank_joins_the_world(world):
    assert lucent.Ranks.launched_as_rank()
    assert lucent.Ranks.built_with_mpi()
    assert 0 <= world.rank < world.size
    assert repr(world) == f"<lucent.Ranks: rank {world.rank} of 3>"


def expect_shares_cover(report, pixels, ranks):
    """The last launch was spread: one share per rank, whose indices cover it once. (Which
    rank took how many pieces depends on timing: on two cores a rank may take none.)"""
    assert len(report.ranks) == ranks.size
    assert sum(share.indices for share in report.ranks) == pixels
    assert sum(share.pieces for share in report.ranks) >= 2 * ranks.size
    assert all(share.busy_ms >= 0 for share in report.ranks)
    assert report.gather_ms >= 0


@pytest.mark.parametrize("sample, options", [
    ("whitted", {}),
    ("pathtracer", {"spp": 4}),  # index-local accumulation: kept rows from the third frame
])
def test_a_sample_across_ranks_is_the_image_of_one_process(world, sample, options):
    alone = lucent.render(sample, size=SIZE, backend="cpu", threads=1, **options)
    spread, report = lucent.render(sample, size=SIZE, backend="cpu", threads=1, ranks=world,
                                   report=True, **options)
    assert spread.shape == alone.shape
    assert spread.tobytes() == alone.tobytes(), f"{sample} on rank {world.rank}"
    assert spread[..., :3].max() > 0
    expect_shares_cover(report, SIZE[0] * SIZE[1], world)


def first_program_context(ranks):
    """The first program of docs/programming-model.md (examples/python/first_launch.py)."""
    ctx = lucent.Context(backend="cpu", threads=1, ranks=ranks)
    ctx.add_module("first_program")
    camera = ctx.create_program("camera")
    ctx.set_ray_type(0, "radiance", payload=camera.module + "::Payload")
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
    ctx["eye"] = (0, 0, 0)
    ctx["scene"] = scene
    ctx["image"] = ctx.create_buffer("output", "float3", SIZE)
    return ctx


def test_a_context_across_ranks_launches_the_image_of_one_process(world):
    alone = first_program_context(None)
    alone.launch(0, *SIZE)
    spread = first_program_context(world)
    report = spread.launch(0, *SIZE)
    expect_shares_cover(report, SIZE[0] * SIZE[1], world)
    assert spread["image"].numpy().tobytes() == alone["image"].numpy().tobytes()
    assert np.count_nonzero(spread["image"].numpy()[..., 0] > 0.2) > 100  # the triangle


def test_an_index_local_image_is_gathered_when_the_host_reads_it(world):
    alone = first_program_context(None)
    alone.launch(0, *SIZE)
    spread = first_program_context(world)
    spread["image"].launch_index_local = True
    for _ in range(4):  # from the third launch on, each rank runs again the rows it took
        report = spread.launch(0, *SIZE)
    expect_shares_cover(report, SIZE[0] * SIZE[1], world)
    # The host read is collective here: every rank makes it and gets the whole image.
    assert spread["image"].numpy().tobytes() == alone["image"].numpy().tobytes()


def test_a_variable_set_on_one_rank_only_is_divergence_on_every_rank(world):
    ctx = first_program_context(world)
    if world.rank == 1:
        ctx["eye"] = (0, 0, 1)
    with pytest.raises(lucent.RankError, match=r"ranks diverged: the launch of rank 1 differs") \
            as caught:
        ctx.launch(0, *SIZE)
    assert caught.value.failed_rank == -1


def test_a_failure_on_rank_2_is_a_rank_error_on_every_rank(world):
    with pytest.raises(lucent.RankError, match=r"^rank 2: disk full$") as caught:
        world.agree("disk full" if world.rank == 2 else None)
    assert caught.value.failed_rank == 2
    assert isinstance(caught.value, lucent.Error)
    world.agree()  # the ranks run on in step


def test_a_scene_missing_on_one_rank_fails_the_render_on_every_rank(world):
    scene = "/missing-on-this-node.obj" if world.rank == 2 else None
    with pytest.raises(lucent.RankError, match=r"^rank 2: .*missing-on-this-node\.obj") as caught:
        lucent.render("pathtracer", scene=scene, size=SIZE, backend="cpu", threads=1, spp=1,
                      ranks=world)
    assert caught.value.failed_rank == 2
    # The next render finds every rank in step.
    image = lucent.render("whitted", size=SIZE, backend="cpu", threads=1, ranks=world)
    assert image[..., :3].max() > 0

"""lucent.Ranks in one process (no mpirun): a group of this process alone, its agreement,
RankError, and the ranks= arguments' checks. The same API across three ranks is
tests/mpi/test_python_ranks.py, which ctest runs as mpi.python under mpirun."""
import pytest

import lucent

SIZE = (64, 48)

pytestmark = pytest.mark.skipif(
    lucent.Ranks.launched_as_rank(), reason="run as one of several ranks: see mpi.python"
)


@pytest.fixture(scope="module")
def world():
    return lucent.Ranks.world()


def test_world_without_a_launcher_is_this_process_alone(world):
    assert (world.rank, world.size) == (0, 1)
    assert repr(world) == "<lucent.Ranks: rank 0 of 1>"
    assert isinstance(lucent.Ranks.built_with_mpi(), bool)


def test_ranks_cannot_be_made_directly():
    with pytest.raises(TypeError):
        lucent.Ranks()


def test_agreement_without_a_failure_returns(world):
    assert world.agree() is None
    assert world.agree(None) is None


def test_a_failure_is_a_rank_error_naming_the_rank(world):
    with pytest.raises(lucent.RankError, match=r"^rank 0: disk full$") as caught:
        world.agree("disk full")
    assert caught.value.failed_rank == 0
    assert isinstance(caught.value, lucent.Error)
    assert isinstance(caught.value, RuntimeError)


def test_a_caught_exception_is_passed_by_its_message(world):
    with pytest.raises(lucent.RankError, match=r"^rank 0: no such scene$"):
        world.agree(FileNotFoundError("no such scene"))
    with pytest.raises(lucent.RankError, match=r"^rank 0: KeyError$"):
        world.agree(KeyError())


@pytest.mark.parametrize("failure, error, words", [
    (3, TypeError, "Ranks.agree: failure must be None"),
    ("", ValueError, "failure must say what failed"),
])
def test_a_bad_failure_names_the_argument(world, failure, error, words):
    with pytest.raises(error, match=words):
        world.agree(failure)


def test_context_and_render_check_their_ranks_argument():
    with pytest.raises(TypeError, match=r"Context: ranks must be a lucent.Ranks .* got 3"):
        lucent.Context(backend="cpu", ranks=3)
    with pytest.raises(TypeError, match=r"render: ranks must be a lucent.Ranks .* got 'all'"):
        lucent.render("whitted", size=SIZE, backend="cpu", ranks="all")


def test_render_over_one_rank_is_the_render_alone(world):
    alone = lucent.render("whitted", size=SIZE, backend="cpu")
    spread, report = lucent.render("whitted", size=SIZE, backend="cpu", ranks=world, report=True)
    assert spread.tobytes() == alone.tobytes()
    assert isinstance(report, lucent.LaunchReport)
    assert report.ranks == []  # one rank: launches run whole, as without ranks
    assert report.exception_count == 0


def test_report_comes_last_beside_the_layers():
    image, layers, report = lucent.render("direct", size=SIZE, backend="cpu", aovs=["depth"],
                                          report=True)
    assert image.shape == (SIZE[1], SIZE[0], 4)
    assert "Z" in layers
    assert isinstance(report, lucent.LaunchReport)


def test_a_failed_render_over_one_rank_is_a_rank_error(world):
    with pytest.raises(lucent.RankError, match=r"^rank 0: .*no-such-scene\.obj") as caught:
        lucent.render("pathtracer", scene="/no-such-scene.obj", size=SIZE, backend="cpu",
                      ranks=world)
    assert caught.value.failed_rank == 0


def test_a_buffer_can_be_declared_index_local():
    ctx = lucent.Context(backend="cpu")
    accumulation = ctx.create_buffer("input_output", "float4", SIZE)
    assert accumulation.launch_index_local is False
    accumulation.launch_index_local = True
    assert accumulation.launch_index_local is True

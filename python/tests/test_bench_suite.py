"""The benchmarks beside bench_rays as calls: lucent.bench_build, bench_spheres, bench_curves,
bench_igi, bench_fog and bench_tea each return the document that `lucent bench <name> --json`
prints, as a dict. What the benchmark counts (triangles, tree sizes, hits, checksums) must
equal the CLI's on the same options; the timings may not."""
import json
import subprocess

import pytest

import lucent
from conftest import BACKEND, REPO

ROOM = REPO / "examples" / "bench-rays" / "room.obj"


def cli_document(cli, *args):
    run = subprocess.run([cli, "bench", *args, "--json"], capture_output=True, text=True, check=True)
    return json.loads(run.stdout)


def same_keys_and(mine, theirs, keys):
    assert list(mine) == list(theirs)  # the same keys, in the same order
    for key in keys:
        assert mine[key] == theirs[key], key


@pytest.mark.skipif(BACKEND != "cpu", reason="the CPU build's tree (the GPU's: gpu-check.sh builder)")
def test_build_counts_the_clis_tree(cli):
    mine = lucent.bench_build(ROOM, repeat=1, threads=2, peer=False)
    theirs = cli_document(cli, "build", "--scene", str(ROOM), "--repeat", "1", "--threads", "2", "--no-peer")
    same_keys_and(mine, theirs, ["triangles", "threads", "sah_cost", "wide_nodes", "leaves", "large_leaves",
                                 "depth"])
    assert mine["threads"] == 2
    assert mine["triangles"] == 2242
    assert mine["build_ms"] > 0
    assert mine["mtris_per_s"] > 0


@pytest.mark.skipif(BACKEND != "cpu", reason="the CPU build's tree")
def test_build_subdivides_into_four_each_level():
    once = lucent.bench_build(str(ROOM), repeat=1, peer=False, subdivide=1)
    assert once["triangles"] == 4 * 2242


def test_spheres_agree_with_the_cli(cli):
    mine = lucent.bench_spheres(backend=BACKEND, count=3000, size=(64, 48), repeat=1)
    theirs = cli_document(cli, "spheres", "--backend", BACKEND, "--count", "3000", "--size", "64x48",
                          "--repeat", "1")
    same_keys_and(mine, theirs, ["spheres", "width", "height", "hit_fraction", "pixels_that_differ"])
    assert 0 < mine["hit_fraction"] < 1
    assert mine["builtin_mrays"]["mrays"] > 0


def test_curves_agree_with_the_cli(cli):
    mine = lucent.bench_curves(backend=BACKEND, segments=2000, curve_type="catmull-rom", size=(64, 48), repeat=1)
    theirs = cli_document(cli, "curves", "--backend", BACKEND, "--segments", "2000", "--type", "catmull-rom",
                          "--size", "64x48", "--repeat", "1")
    same_keys_and(mine, theirs, ["curve_type", "segments", "primary_hit_fraction", "diffuse_hit_fraction"])
    assert mine["curve_type"] == "Catmull-Rom"
    assert 0 < mine["primary_hit_fraction"] < 1


def test_tea_makes_the_clis_numbers(cli):
    mine = lucent.bench_tea(backend=BACKEND, megabytes=2, rounds=4, device=3, seed=7)
    theirs = cli_document(cli, "tea", "--backend", BACKEND, "--megabytes", "2", "--rounds", "4", "--device", "3",
                          "--seed", "7")
    same_keys_and(mine, theirs, ["megabytes", "rounds", "fixed_checksum", "generated_checksum"])
    other_seed = lucent.bench_tea(backend=BACKEND, megabytes=2, rounds=4, device=3, seed=8)
    assert other_seed["fixed_checksum"] == mine["fixed_checksum"]
    assert other_seed["generated_checksum"] != mine["generated_checksum"]


def test_igi_measures_every_configuration_at_every_vpl_count(cli):
    mine = lucent.bench_igi(backend=BACKEND, size=(48, 32), frames=1, vpls=[4, 8])
    theirs = cli_document(cli, "igi", "--backend", BACKEND, "--size", "48x32", "--frames", "1", "--vpls", "4,8")
    same_keys_and(mine, theirs, ["scene", "width", "height", "frames"])
    rows = [(r["configuration"], r["vpls"]) for r in mine["rows"]]
    assert rows == [(r["configuration"], r["vpls"]) for r in theirs["rows"]]
    assert {v for _, v in rows} == {4, 8}
    assert all(r["frame_ms"] > 0 for r in mine["rows"])


def test_fog_measures_its_four_configurations(cli):
    mine = lucent.bench_fog(backend=BACKEND, size=(48, 32), frames=2)
    theirs = cli_document(cli, "fog", "--backend", BACKEND, "--size", "48x32", "--frames", "2")
    same_keys_and(mine, theirs, ["width", "height", "frames"])
    assert [r["configuration"] for r in mine["rows"]] == [r["configuration"] for r in theirs["rows"]]
    assert len(mine["rows"]) == 4
    assert all(r["fps"] > 0 for r in mine["rows"])


@pytest.mark.parametrize("call, error, words", [
    (lambda: lucent.bench_build(ROOM, repeat=0), lucent.Error, "repeat (--repeat) is 0"),
    (lambda: lucent.bench_build(ROOM, subdivide=6), lucent.Error, "subdivide (--subdivide) is 6; it must lie in [0, 5]"),
    (lambda: lucent.bench_build(ROOM, backend="gpu"), ValueError, "bench_build: backend"),
    (lambda: lucent.bench_build(ROOM, size=(0, 8)), lucent.Error, "the image size (size, --size) is 0x8"),
    (lambda: lucent.bench_build(3), TypeError, "bench_build: scene must be an OBJ file's path"),
    (lambda: lucent.bench_spheres(count=0), lucent.Error, "count (--count) is 0"),
    (lambda: lucent.bench_spheres(repeat=1001), lucent.Error, "repeat (--repeat) is 1001"),
    (lambda: lucent.bench_curves(curve_type="bezier"), ValueError, "curve_type is 'bezier'"),
    (lambda: lucent.bench_curves(segments=0), lucent.Error, "segments (--segments) is 0"),
    (lambda: lucent.bench_tea(megabytes=0), lucent.Error, "megabytes (--megabytes) is 0"),
    (lambda: lucent.bench_tea(rounds=65), lucent.Error, "rounds (--rounds) is 65"),
    (lambda: lucent.bench_igi(vpls=[]), lucent.Error, "vpls (--vpls) is empty"),
    (lambda: lucent.bench_igi(vpls=[30, 0]), lucent.Error, "a VPL count (vpls, --vpls) is 0"),
    (lambda: lucent.bench_igi(interleave=9), lucent.Error, "interleave (--interleave) is 9"),
    (lambda: lucent.bench_igi(frames=0), lucent.Error, "frames (--frames) is 0"),
    (lambda: lucent.bench_igi(b"cornell"), TypeError, "bench_igi: scene must be"),
    (lambda: lucent.bench_fog(size=(0, 8)), lucent.Error, "the image size (size, --size) is 0x8"),
    (lambda: lucent.bench_fog(threads=5000), lucent.Error, "threads (--threads) is 5000"),
])
def test_bad_arguments_name_the_argument(call, error, words):
    with pytest.raises(error) as e:
        call()
    assert words in str(e.value)


def test_a_missing_scene_is_named(tmp_path):
    with pytest.raises(lucent.Error, match="nothing.obj"):
        lucent.bench_build(tmp_path / "nothing.obj")
    with pytest.raises(lucent.Error, match="nothing.json"):
        lucent.bench_igi(tmp_path / "nothing.json", size=(8, 8), frames=1, vpls=[1])


@pytest.mark.skipif(BACKEND != "cpu", reason="two CPU devices; the GPUs' spread: gpu-check.sh multi")
def test_igi_and_fog_spread_over_devices(cli):
    mine = lucent.bench_fog(size=(48, 32), frames=1, devices=["cpu", "cpu"])
    theirs = cli_document(cli, "fog", "--size", "48x32", "--frames", "1", "--devices", "cpu,cpu")
    assert mine["backend"] == theirs["backend"]
    assert mine["backend"] != lucent.bench_fog(size=(48, 32), frames=1)["backend"]
    igi = lucent.bench_igi(size=(48, 32), frames=1, vpls=[4], devices="cpu,cpu")
    assert igi["backend"] == mine["backend"]
    with pytest.raises(lucent.Error, match="gpu"):
        lucent.bench_fog(size=(48, 32), frames=1, devices="cpu,gpu")


@pytest.mark.skipif(lucent.Ranks.launched_as_rank(), reason="one process alone")
def test_igi_over_one_rank_measures_the_same_rows():
    world = lucent.Ranks.world()
    spread = lucent.bench_igi(size=(48, 32), frames=1, vpls=[4], backend="cpu", ranks=world)
    alone = lucent.bench_igi(size=(48, 32), frames=1, vpls=[4], backend="cpu")
    assert [r["configuration"] for r in spread["rows"]] == [r["configuration"] for r in alone["rows"]]
    with pytest.raises(TypeError, match="bench_igi: ranks must be a lucent.Ranks"):
        lucent.bench_igi(size=(48, 32), frames=1, vpls=[4], ranks="all")
    with pytest.raises(lucent.RankError, match=r"^rank 0: .*nothing\.json"):
        lucent.bench_igi("/nothing.json", size=(8, 8), frames=1, vpls=[1], backend="cpu", ranks=world)

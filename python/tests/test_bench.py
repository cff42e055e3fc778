"""lucent.bench_rays: `lucent bench rays --json` as a call, its document as a dict."""
import json
import subprocess

import pytest

import lucent
from conftest import BACKEND, REPO

ROOM = REPO / "examples" / "bench-rays" / "room.obj"  # with its camera in cameras.txt
SIZE = (96, 72)


def counts(document):
    """The checksums of Lucent's kernels: what must not depend on who ran the benchmark."""
    return {kind: {k: v for k, v in document["lucent"][kind].items() if k in ("hits", "occluded", "sum_t")}
            for kind in ("primary", "shadow", "diffuse")}


def test_the_document_equals_the_clis(cli):
    mine = lucent.bench_rays(ROOM, size=SIZE, repeat=1, backend=BACKEND)
    run = subprocess.run([cli, "bench", "rays", "--scene", str(ROOM), "--size", "96x72", "--repeat", "1",
                          "--backend", BACKEND, "--json"], capture_output=True, text=True, check=True)
    theirs = json.loads(run.stdout)
    assert list(mine) == list(theirs)  # the same keys, in the same order
    assert counts(mine) == counts(theirs)
    assert mine["lucent"]["primary"]["hits"] > 0
    assert mine["lucent"]["diffuse"]["hits"] > 0
    if "embree" in mine:
        assert mine["checksums_agree"] is True
        assert mine["ratio"]["primary"] > 0


@pytest.mark.skipif(BACKEND != "cpu", reason="the CPU's streams and engine path")
def test_streams_and_programs_agree_with_the_kernels():
    d = lucent.bench_rays(str(ROOM), size=SIZE, repeat=1, programs=True, threads=1)
    assert d["threads"] == 1
    assert d["streams"]["checksums_agree_with_kernels"] is True
    assert d["programs"]["checksums_agree"] is True
    assert d["programs"]["primary"]["hits"] == d["lucent"]["primary"]["hits"]
    # The module's deferred entries (trace_deferred, occluded_deferred): the same answers.
    assert d["programs_deferred"]["checksums_agree"] is True
    assert d["programs_deferred"]["shadow"]["occluded"] == d["lucent"]["shadow"]["occluded"]


def test_a_camera_given_whole_replaces_cameras_txt():
    given = lucent.bench_rays(ROOM, size=SIZE, repeat=1, peer=False, backend=BACKEND,
                              eye=(0, 1.5, 5.5), look=(0, 1.2, 0), up=(0, 1, 0), fov=50, light=(0, 2.8, 0.5))
    assert "embree" not in given
    assert counts(given) == counts(lucent.bench_rays(ROOM, size=SIZE, repeat=1, peer=False, backend=BACKEND))
    turned = lucent.bench_rays(ROOM, size=SIZE, repeat=1, peer=False, backend=BACKEND,
                               eye=(1.5, 2.5, 3), look=(0, 1, 0), up=(0, 1, 0), fov=50, light=(0, 2.8, 0.5))
    assert counts(turned) != counts(given)


@pytest.mark.parametrize("kwargs, error, words", [
    (dict(size=(0, 72)), lucent.Error, "size"),
    (dict(repeat=0), lucent.Error, "repeat"),
    (dict(backend="gpu"), lucent.Error, 'backend (--backend) is "gpu"'),
    (dict(builder="fast"), ValueError, 'builder is "fast"'),
    (dict(eye=(0, 1, 5)), ValueError, "given eye, missing look up fov light"),
    (dict(eye=(0, 1), look=(0, 1, 0), up=(0, 1, 0), fov=50, light=(0, 2, 0)), ValueError, "eye must be three numbers"),
    (dict(eye=(0, 1, 5), look=(0, 1, 0), up=(0, 1, 0), fov=180, light=(0, 2, 0)), lucent.Error, "fov (--fov) is 180"),
])
def test_bad_arguments_name_the_argument(kwargs, error, words):
    with pytest.raises(error) as e:
        lucent.bench_rays(ROOM, **{"size": SIZE, "repeat": 1, **kwargs})
    assert words in str(e.value)


@pytest.mark.parametrize("scene", [3, b"room.obj", None])
def test_a_scene_that_is_not_a_path_is_a_type_error(scene):
    with pytest.raises(TypeError, match="bench_rays: scene must be"):
        lucent.bench_rays(scene)


def test_a_missing_scene_is_named(tmp_path):
    missing = tmp_path / "nothing.obj"
    with pytest.raises(lucent.Error, match="nothing.obj"):
        lucent.bench_rays(missing)

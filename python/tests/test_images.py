"""lucent.read_image and lucent.compare give what `lucent compare` gives, on files and on
arrays, and refuse bad arguments by name."""
import json
import subprocess

import numpy as np
import pytest

import lucent
from conftest import BACKEND


def test_compare_is_the_cli_on_the_same_files(tmp_path, cli):
    a, b = tmp_path / "a.pfm", tmp_path / "b.pfm"
    for out, vpls in ((a, 64), (b, 8)):
        subprocess.run([cli, "render", "--sample", "igi", "--size", "48x40", "--backend", BACKEND,
                        "--set", f"vpls={vpls}", "-q", "--out", str(out)], check=True)
    figures = json.loads(subprocess.run([cli, "compare", str(a), str(b), "--json"], check=True,
                                        capture_output=True, text=True).stdout)
    ours = lucent.compare(a, str(b))
    for key in ("rmse", "relmse", "psnr_db", "flip_mean", "flip_median", "flip_max"):
        assert ours[key] == pytest.approx(figures[key], rel=1e-12), key
    assert ours["flip"].shape == (40, 48) and ours["flip"].dtype == np.float32
    assert 0 < ours["flip_mean"] < 1
    # Arrays give the same figures as the files they were read from.
    from_arrays = lucent.compare(lucent.read_image(a), lucent.read_image(b))
    np.testing.assert_array_equal(from_arrays["flip"], ours["flip"])
    rgba = np.concatenate([lucent.read_image(b), np.ones((40, 48, 1), np.float32)], axis=2)
    assert lucent.compare(lucent.read_image(a), rgba)["rmse"] == ours["rmse"]  # alpha ignored


def test_compare_of_render_arrays():
    image = lucent.render("direct", size=(32, 32), backend=BACKEND)
    same = lucent.compare(image, image)
    assert same["rmse"] == 0 and same["flip_max"] == 0 and same["psnr_db"] == float("inf")
    darker = lucent.compare(image, image * np.float32(0.5))
    assert darker["flip_mean"] > 0.05 and darker["rmse"] > 0
    assert lucent.compare(image, image * np.float32(0.5), ppd=10)["flip_mean"] != darker["flip_mean"]


def test_bad_images_are_named():
    good = np.zeros((4, 4, 3), np.float32)
    with pytest.raises(TypeError, match="compare: test must be a file path or an"):
        lucent.compare(good, 3)
    with pytest.raises(TypeError, match="compare: reference must be a float array"):
        lucent.compare(np.zeros((4, 4, 3), np.uint8), good)
    with pytest.raises(ValueError, match=r"compare: test must be an \(H, W, 3\) or \(H, W, 4\) array"):
        lucent.compare(good, np.zeros((4, 4), np.float32))
    with pytest.raises(lucent.Error, match="the images differ in size"):
        lucent.compare(good, np.zeros((4, 5, 3), np.float32))
    nan = good.copy()
    nan[1, 2, 0] = np.nan
    with pytest.raises(lucent.Error, match="1 pixels that are not finite"):
        lucent.compare(good, nan)
    with pytest.raises(ValueError, match="ppd must be in"):
        lucent.compare(good, good, ppd=0)
    with pytest.raises(lucent.Error, match="no such file"):
        lucent.read_image("/nonexistent/x.exr")


def test_the_path_tracer_converges_by_flip_and_relmse():
    """More samples per pixel bring the path tracer's image nearer its converged one."""
    size = (48, 48)
    reference = lucent.render("pathtracer", size=size, spp=512, backend=BACKEND)
    errors = [lucent.compare(reference, lucent.render("pathtracer", size=size, spp=spp, backend=BACKEND))
              for spp in (2, 16, 128)]
    for coarse, fine in zip(errors, errors[1:]):
        assert fine["flip_mean"] < coarse["flip_mean"]
        assert fine["relmse"] < coarse["relmse"]

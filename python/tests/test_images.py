"""lucent.read_image and lucent.compare give what `lucent compare` gives, on files and on
arrays, and refuse bad arguments by name."""
import json
import struct
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


def test_write_image_writes_what_read_image_reads(tmp_path):
    image = lucent.render("whitted", size=(40, 30), backend="cpu")
    lucent.write_image(tmp_path / "w.pfm", image)
    np.testing.assert_array_equal(lucent.read_image(tmp_path / "w.pfm"), image[:, :, :3])
    lucent.write_image(str(tmp_path / "w.exr"), image[:, :, :3])
    np.testing.assert_array_equal(lucent.read_image(tmp_path / "w.exr"), image[:, :, :3])
    lucent.write_image(tmp_path / "w.png", image)
    assert lucent.compare(tmp_path / "w.png", image)["psnr_db"] > 40  # 8-bit sRGB


def exr_channels(path):
    """The channel names of an OpenEXR file's header (its "channels" chlist attribute)."""
    data = path.read_bytes()
    pos = 8  # magic number and version
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name, pos = data[pos:end].decode(), end + 1
        pos = data.index(b"\0", pos) + 1  # the attribute's type name
        size, = struct.unpack_from("<i", data, pos)
        pos += 4
        if name == "channels":
            names = []
            while data[pos] != 0:
                end = data.index(b"\0", pos)
                names.append(data[pos:end].decode())
                pos = end + 1 + 16  # pixel type, pLinear and reserved, x and y sampling
            return sorted(names)
        pos += size
    return []


def test_write_image_puts_the_layers_into_an_exr(tmp_path, cli):
    image, layers = lucent.render("direct", size=(32, 24), backend="cpu", aovs=["depth", "normal"])
    lucent.write_image(tmp_path / "d.exr", image, layers=layers, alpha=True)
    subprocess.run([cli, "render", "--sample", "direct", "--size", "32x24", "--backend", "cpu", "--aov",
                    "depth,normal", "--out", str(tmp_path / "cli.exr")], capture_output=True, check=True)
    assert exr_channels(tmp_path / "d.exr") == exr_channels(tmp_path / "cli.exr")
    assert {"A", "R", "G", "B", "Z", "Nx"} <= set(exr_channels(tmp_path / "d.exr"))
    np.testing.assert_array_equal(lucent.read_image(tmp_path / "d.exr"), lucent.read_image(tmp_path / "cli.exr"))
    lucent.write_image(tmp_path / "rgb.exr", image)
    assert exr_channels(tmp_path / "rgb.exr") == ["B", "G", "R"]


@pytest.mark.parametrize("args, error, words", [
    (lambda d: (d / "x.png", np.zeros((4, 4), np.float32)), ValueError, "write_image: image must be an (H, W, 3)"),
    (lambda d: (d / "x.png", np.zeros((4, 4, 3), np.uint8)), TypeError, "write_image: image must be a float array"),
    (lambda d: (3, np.zeros((4, 4, 3), np.float32)), TypeError, "write_image: path must be an image file's path"),
    (lambda d: (d / "x.gif", np.zeros((4, 4, 3), np.float32)), lucent.Error, "x.gif"),
    (lambda d: (d / "no" / "x.png", np.zeros((4, 4, 3), np.float32)), lucent.Error, "x.png"),
])
def test_write_image_refuses_bad_arguments_and_writes_nothing(tmp_path, args, error, words):
    path, image = args(tmp_path)
    with pytest.raises(error) as e:
        lucent.write_image(path, image)
    assert words in str(e.value)
    assert list(tmp_path.iterdir()) == []


def test_write_image_checks_the_layers(tmp_path):
    image = np.zeros((4, 6, 3), np.float32)
    with pytest.raises(ValueError, match="layer 'Z' must be a \\(4, 6\\) float array"):
        lucent.write_image(tmp_path / "x.exr", image, layers={"Z": np.zeros((6, 4), np.float32)})
    with pytest.raises(lucent.Error, match="exr"):
        lucent.write_image(tmp_path / "x.png", image, layers={"Z": np.zeros((4, 6), np.float32)})
    with pytest.raises(TypeError, match="layers must be a dict"):
        lucent.write_image(tmp_path / "x.exr", image, layers=[1])
    with pytest.raises(ValueError, match="alpha=True needs an \\(H, W, 4\\) image"):
        lucent.write_image(tmp_path / "x.exr", image, alpha=True)
    assert list(tmp_path.iterdir()) == []

"""lucent.render() gives the very floats `lucent render --out x.pfm` writes for the same
settings, for every sample; lucent.samples() lists them with their options."""
import subprocess

import numpy as np
import pytest

import lucent
from conftest import BACKEND, REPO


def read_pfm(path):
    """A PFM file (rows from the bottom up) as an (H, W, 3) float32 array, row 0 at the top."""
    data = path.read_bytes()
    header, rest = data.split(b"\n", 1)
    size, rest = rest.split(b"\n", 1)
    scale, pixels = rest.split(b"\n", 1)
    assert header == b"PF" and float(scale) < 0  # RGB, little-endian
    w, h = (int(s) for s in size.split())
    return np.frombuffer(pixels, "<f4").reshape(h, w, 3)[::-1]


# (sample, size, spp, options): small images, each sample's default scene.
CASES = [
    ("whitted", (64, 48), 0, {}),
    ("direct", (48, 48), 0, {}),
    ("igi", (64, 64), 0, {"vpls": 16}),
    ("igi", (64, 64), 0, {"vpls": 16, "downsample": 2, "interleave": 3, "imperfect_visibility": True}),
    ("igi", (64, 64), 0, {"vpls": 16, "imperfect_visibility": 3, "visibility_map": 32}),
    ("radiosity", (48, 48), 0, {}),
    ("pathtracer", (32, 32), 4, {}),
    ("hair", (48, 27), 2, {"strands": 500, "curve_type": "catmull-rom", "light_linking": False}),
    ("fog", (48, 36), 0, {}),
]


@pytest.mark.parametrize("sample, size, spp, options", CASES,
                         ids=[f"{c[0]}-{'-'.join(c[3]) or 'defaults'}" for c in CASES])
def test_render_is_the_cli_image(tmp_path, cli, sample, size, spp, options):
    image = lucent.render(sample, size=size, backend=BACKEND, spp=spp, **options)
    assert image.shape == (size[1], size[0], 4) and image.dtype == np.float32
    assert np.all(image[..., 3] == 1)
    out = tmp_path / f"{sample}.pfm"
    args = [cli, "render", "--sample", sample, "--size", f"{size[0]}x{size[1]}", "--backend",
            BACKEND, "--out", str(out)]
    if spp:
        args += ["--spp", str(spp)]
    for name, value in options.items():
        args += ["--set", f"{name}={int(value) if isinstance(value, bool) else value}"]
    subprocess.run(args, check=True, capture_output=True)
    np.testing.assert_array_equal(image[..., :3], read_pfm(out))
    assert image[..., :3].max() > 0  # not black


def test_render_a_scene_by_name(tmp_path, cli):
    a = lucent.render("direct", scene="cornell-point", size=(32, 32), backend=BACKEND)
    out = tmp_path / "d.pfm"
    subprocess.run([cli, "render", "--sample", "direct", "--scene", "cornell-point", "--size",
                    "32x32", "--backend", BACKEND, "--out", str(out)], check=True, capture_output=True)
    np.testing.assert_array_equal(a[..., :3], read_pfm(out))


@pytest.mark.parametrize("sample", ["igi", "whitted"])
def test_render_with_a_camera_is_the_cli_image(tmp_path, cli, sample):
    camera = dict(eye=(100, 400, -300), look=(278, 200, 280), up=(0, 1, 0), fov=50) if sample == "igi" \
        else dict(fov=25, up=(0.1, 1, 0))
    image = lucent.render(sample, size=(40, 32), backend=BACKEND, **camera)
    out = tmp_path / "c.pfm"
    args = [cli, "render", "--sample", sample, "--size", "40x32", "--backend", BACKEND, "--out", str(out)]
    for name, value in camera.items():
        args += [f"--{name}", ",".join(str(v) for v in value) if isinstance(value, tuple) else str(value)]
    subprocess.run(args, check=True, capture_output=True)
    np.testing.assert_array_equal(image[..., :3], read_pfm(out))
    assert not np.array_equal(image, lucent.render(sample, size=(40, 32), backend=BACKEND))


def test_a_bad_camera_is_a_value_error():
    with pytest.raises(ValueError, match=r"render: eye must be three numbers \(x, y, z\); got \(1, 2\)"):
        lucent.render("direct", size=(8, 8), eye=(1, 2))
    with pytest.raises(ValueError, match="render: look must be three numbers"):
        lucent.render("direct", size=(8, 8), look="abc")
    with pytest.raises(ValueError, match=r"render: camera: eye and look are the same point \(1,2,3\)"):
        lucent.render("direct", size=(8, 8), eye=(1, 2, 3), look=np.array([1, 2, 3]))
    with pytest.raises(ValueError, match=r"camera: fov 0 degrees; the vertical field of view must be in \(0, 180\)"):
        lucent.render("fog", size=(8, 8), fov=0)


def test_samples_lists_every_sample_with_its_options():
    listed = lucent.samples()
    assert set(listed) >= {"whitted", "direct", "igi", "radiosity", "pathtracer", "hair", "fog"}
    igi = listed["igi"]
    assert igi["description"]
    vpls = igi["options"]["vpls"]
    assert vpls["kind"] == "integer" and isinstance(vpls["default"], int) and vpls["default"] > 0
    assert vpls["range"][0] <= vpls["default"] <= vpls["range"][1]
    assert vpls["help"]
    kinds = {o["kind"] for s in listed.values() for o in s["options"].values()}
    assert kinds >= {"integer", "number", "switch"}
    for s in listed.values():
        for o in s["options"].values():
            if o["kind"] == "switch":
                assert isinstance(o["default"], bool)


def test_render_a_gltf_scene_by_path(tmp_path, cli):
    """A .gltf path is a scene like any other: scripts/make_instanced_gltf.py writes 4
    instanced spheres with a camera and a point light; the image is the CLI's, spheres lit,
    and camera=N picks the file's camera N (out of range: an error naming the count)."""
    path = tmp_path / "spheres.gltf"
    subprocess.run(["/usr/bin/python3", str(REPO / "scripts" / "make_instanced_gltf.py"),
                    "--instances", "4", "--rings", "8", "--segments", "16", "--out", str(path)],
                   check=True, capture_output=True)
    image = lucent.render("direct", scene=str(path), size=(32, 32), backend=BACKEND)
    out = tmp_path / "g.pfm"
    subprocess.run([cli, "render", "--sample", "direct", "--scene", str(path), "--size", "32x32",
                    "--backend", BACKEND, "--camera", "0", "--out", str(out)], check=True,
                   capture_output=True)
    np.testing.assert_array_equal(image[..., :3], read_pfm(out))
    red = image[..., 0] > 2 * image[..., 1] + 0.01  # the spheres are red, the ground grey
    assert red.sum() > 20
    with pytest.raises(Exception, match="--camera 1: scene 'spheres' has 1 camera of its own"):
        lucent.render("direct", scene=str(path), size=(8, 8), backend=BACKEND, camera=1)


@pytest.mark.skipif(BACKEND != "cpu", reason="two CPU devices; the GPUs' spread: gpu-check.sh multi")
def test_render_over_two_devices_is_the_image_of_one():
    """devices= (--devices): each launch spread over the devices, the image the same."""
    one = lucent.render("whitted", size=(64, 48), backend="cpu")
    two, report = lucent.render("whitted", size=(64, 48), backend="cpu", devices=["cpu", "cpu"], report=True)
    assert two.tobytes() == one.tobytes()
    assert len(report.devices) == 2
    with pytest.raises(lucent.Error, match="gpu"):
        lucent.render("whitted", size=(64, 48), backend="cpu", devices="cpu,gpu")

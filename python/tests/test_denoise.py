"""lucent.render(..., denoise=True) and aovs=[...]: the same images and layers as `lucent
render --denoise` and `--aov`, and the denoiser's gain on a 4-spp Cornell box."""
import numpy as np
import pytest

import lucent
from conftest import BACKEND


def relmse(reference, test):
    """The relative MSE of `lucent compare` (scene/image_compare.h), over RGB."""
    r, t = reference[..., :3], test[..., :3]
    return float(np.mean((t - r) ** 2 / (r ** 2 + 0.01)))


def test_denoise_brings_four_spp_nearer_the_reference():
    reference = lucent.render("pathtracer", size=(64, 64), backend=BACKEND, spp=256)
    noisy = lucent.render("pathtracer", size=(64, 64), backend=BACKEND, spp=4)
    # Two passes: the default's third blurs the soft shadows of so small an image.
    denoised = lucent.render("pathtracer", size=(64, 64), backend=BACKEND, spp=4, denoise=True,
                             denoise_passes=2)
    assert denoised.shape == noisy.shape == (64, 64, 4)
    assert relmse(reference, denoised) < relmse(reference, noisy) / 3


def test_aovs_return_the_layers_and_coverage_as_alpha():
    image, layers = lucent.render("pathtracer", size=(24, 16), backend=BACKEND, spp=1,
                                  aovs=["albedo", "normal", "depth", "position", "instance"])
    assert image.shape == (16, 24, 4)
    assert set(layers) == {"Albedo.R", "Albedo.G", "Albedo.B", "Nx", "Ny", "Nz", "Px", "Py",
                           "Pz", "Z", "InstanceId"}
    for values in layers.values():
        assert values.shape == (16, 24) and values.dtype == np.float32
    alpha = image[..., 3]
    assert set(np.unique(alpha)) <= {0.0, 1.0}
    hit = alpha == 1.0
    assert hit.sum() > hit.size // 2
    n2 = layers["Nx"] ** 2 + layers["Ny"] ** 2 + layers["Nz"] ** 2
    np.testing.assert_allclose(n2[hit], 1.0, atol=1e-4)
    assert (layers["Z"][hit] > 0).all() and (layers["Z"][~hit] == 0).all()
    assert (layers["InstanceId"][~hit] == -1).all()


def test_bad_aov_and_a_sample_without_a_gbuffer_are_value_errors():
    with pytest.raises(ValueError, match=r"aovs 'albdo': unknown AOV 'albdo' \(did you mean 'albedo'\?\)"):
        lucent.render("pathtracer", size=(8, 8), backend=BACKEND, aovs=["albdo"])
    with pytest.raises(ValueError, match="has no G-buffer pass"):
        lucent.render("whitted", size=(8, 8), backend=BACKEND, denoise=True)
    with pytest.raises(ValueError, match="denoise_passes"):
        lucent.render("pathtracer", size=(8, 8), backend=BACKEND, denoise=True, denoise_passes=11)

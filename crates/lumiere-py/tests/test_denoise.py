"""lumiere.denoise: OIDN through pyoidn, and a clear error without it."""

import sys

import numpy as np
import pytest

import lumiere
from conftest import optional


def test_a_clear_error_without_pyoidn(monkeypatch):
    monkeypatch.setitem(sys.modules, "pyoidn", None)  # makes `import pyoidn` fail
    with pytest.raises(ImportError, match="needs pyoidn .*: pip install pyoidn"):
        lumiere.denoise(np.zeros((4, 4, 3), dtype=np.float32))


def test_what_is_not_an_image_is_refused_before_pyoidn_is_needed(monkeypatch):
    monkeypatch.setitem(sys.modules, "pyoidn", None)  # the checks come first: no pyoidn needed
    for bad in (np.array([[[None] * 3]]), np.ones((2, 2, 3), complex), [[["1", "2", "3"]]]):
        with pytest.raises(lumiere.LumiereError, match="color must hold numbers"):
            lumiere.denoise(bad)
    with pytest.raises(lumiere.LumiereError, match="albedo must hold numbers"):
        lumiere.denoise(np.zeros((2, 2, 3)), np.full((2, 2, 3), None))
    with pytest.raises(lumiere.LumiereError, match="quality must be one of high, balanced, fast, got 'bogus'"):
        lumiere.denoise(np.zeros((2, 2, 3)), quality="bogus")


def test_denoising_brings_a_noisy_render_closer_to_the_reference():
    optional("pyoidn", "pip install pyoidn")
    scene = lumiere.builtin()
    reference = lumiere.render(scene, spp=256, size=(64, 48), seed=1)
    noisy = lumiere.render(scene, spp=4, size=(64, 48), aovs=("albedo", "normal"))
    denoised = lumiere.denoise(noisy["color"], noisy["albedo"], noisy["normal"])
    assert denoised.shape == (48, 64, 3) and denoised.dtype == np.float32

    def rmse(image):
        return float(np.sqrt(np.mean((image - reference) ** 2)))

    assert rmse(denoised) < 0.7 * rmse(noisy["color"]), (rmse(denoised), rmse(noisy["color"]))
    with pytest.raises(lumiere.LumiereError, match="normal needs albedo"):
        lumiere.denoise(noisy["color"], normal=noisy["normal"])
    with pytest.raises(lumiere.LumiereError, match="albedo has shape"):
        lumiere.denoise(noisy["color"], noisy["albedo"][:10])

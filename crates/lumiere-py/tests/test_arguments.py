"""A wrong-typed or out-of-range argument is a LumiereError naming the argument, never a bare
OverflowError, TypeError or UnicodeEncodeError from deep in the conversion to native values."""

import numpy as np
import pytest

import lumiere
from lumiere import _lumiere

HUGE = 10**400
VERTICES = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float32)
SMALL = {"spp": 1, "size": (8, 6)}


def look_at(**kwargs):
    return lumiere.Camera.look_at(**{"eye": (0, 1, 4), "target": (0, 1, 0), "size": (8, 6), **kwargs})


def render(**kwargs):
    return lumiere.render(lumiere.builtin(), **{**SMALL, **kwargs})


def write_image(**kwargs):
    return lumiere.write_image("x.png", np.zeros((2, 2, 3), np.float32), **kwargs)


def from_arrays(**kwargs):
    return lumiere.Scene.from_arrays(VERTICES, [[0, 1, 2]], **kwargs)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: look_at(fov=HUGE), "fov must be at most"),
        (lambda: look_at(eye=(HUGE, 0, 1)), "eye must fit in float32"),
        # Finite floats beyond float32's range: named with their value, not as the infinity they
        # would become.
        (lambda: look_at(fov=1e300), r"fov must fit in float32 .*got 1e\+300"),
        (lambda: lumiere.Camera.framing(lumiere.builtin(), fov=1e300), r"fov must fit in float32 .*got 1e\+300"),
        (lambda: write_image(exposure=-1e39), r"exposure must fit in float32 .*got -1e\+39"),
        (lambda: render(mode="ao", ao_distance=1e39), r"ao_distance must fit in float32 .*got 1e\+39"),
        (lambda: render(spp=None, time=HUGE), "time must be at most"),
        (lambda: render(spp=None, noise=HUGE), "noise must be at most"),
        (lambda: render(mode="ao", ao_distance=HUGE), "ao_distance must be at most"),
        (lambda: lumiere.builtin(emission={"light.001": (HUGE, 1, 1)}), r"emission\['light.001'\] must fit in float32"),
        (lambda: write_image(exposure=HUGE), "exposure must be at most"),
        (lambda: render(mode="ao", ao_distance="x"), "ao_distance must be a number, got 'x'"),
        (lambda: write_image(exposure="1"), "exposure must be a number, got '1'"),
        (lambda: render(mode="direct", light_sampling=3), "light_sampling must be a string, got 3"),
        (lambda: render(aovs=[1]), r"aovs\[0\] must be a string, got 1"),
        (lambda: render(mode=5), "mode must be a string, got 5"),
        (lambda: from_arrays(name=5), "name must be a string, got 5"),
        (lambda: lumiere.render(lumiere.Scene.from_arrays(VERTICES, np.zeros((0, 3), np.int64))), "the scene has no faces"),
        (lambda: write_image(tonemap=None), "tonemap must be a string, got None"),
        (lambda: from_arrays(materials=["a\udcffb"]), r"materials\[0\]\['name'\] must be valid Unicode text"),
        (lambda: from_arrays(name="a\udcffb"), "name must be valid Unicode text"),
        (lambda: lumiere.builtin(emission={"a\udcffb": (1, 1, 1)}), "emission name must be valid Unicode text"),
        (lambda: lumiere.Scene.from_arrays([[0, 0, "x"]], [[0, 0, 0]]), "vertices must be an array of numbers"),
        (lambda: lumiere.write_image("x.png", np.array([[[None] * 3]])), "image must hold numbers, got an array of object"),
        (lambda: lumiere.write_image("x.png", [[["1", "2", "3"]]]), "image must hold numbers, got an array of <U1"),
        (lambda: lumiere.write_image("x.png", np.zeros((0, 2**33, 3), np.float32)), "image size 8589934592x0 is too large"),
        (lambda: _lumiere.NativeFilm(-1, 2), "width must be an integer between 0 and 4294967295, got -1"),
        (lambda: _lumiere.NativeFilm(2, 2**64), "height must be an integer between 0 and 4294967295"),
    ],
)
def test_a_bad_argument_is_a_lumiere_error_naming_it(tmp_path, monkeypatch, call, message):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(lumiere.LumiereError, match=message):
        call()
    assert not (tmp_path / "x.png").exists()


def test_native_pass_ranges_refuse_counts_beyond_their_range():
    scene, camera = lumiere.builtin(), lumiere.Camera.builtin((8, 6))
    options = _lumiere.NativeOptions("hits", 1, 0, None)
    with pytest.raises(lumiere.LumiereError, match="count must be an integer between 0 and 4294967295, got 4294967296"):
        _lumiere.render_passes(scene._native, camera._native, options, 0, 2**32, 1)
    with pytest.raises(lumiere.LumiereError, match="first must be an integer between 0 and 4294967295, got -1"):
        _lumiere.render_passes(scene._native, camera._native, options, -1, 1, 1)


def test_a_checkpoint_holds_the_film_of_the_camera_it_names(tmp_path):
    # A film saved with a camera of another size made a checkpoint that no render could resume.
    film, path = _lumiere.NativeFilm(2, 2), tmp_path / "c.ckpt"
    options = _lumiere.NativeOptions("hits", 1, 0, None)
    camera = lumiere.Camera.builtin((3, 2))._native
    with pytest.raises(lumiere.LumiereError, match=r"the film is 2x2, but the camera's image is 3x2"):
        film.save_checkpoint(str(path), lumiere.builtin()._native, camera, options)
    assert not path.exists()

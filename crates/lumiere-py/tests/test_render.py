"""lumiere.render: shapes and types, the CLI's exact values, options, errors, progress, the GIL
and Ctrl-C."""

import contextlib
import math
import os
import pickle
import signal
import subprocess
import sys
import textwrap
import threading
import time
import warnings

import numpy as np
import pytest

import lumiere
from conftest import read_pfm


def bits(image):
    return np.ascontiguousarray(image, dtype=np.float32).view(np.uint32)


def test_three_lines_render_the_cornell_box():
    image = lumiere.render(lumiere.builtin(), spp=2, size=(64, 48))
    assert image.shape == (48, 64, 3)
    assert image.dtype == np.float32
    assert image.flags.c_contiguous and image.flags.writeable
    assert np.isfinite(image).all() and image.mean() > 0.05, "the lit box is not black"


@pytest.mark.parametrize(
    "flags, kwargs",
    [
        (["--spp", "4"], dict(spp=4)),
        (["--mode", "direct", "--samples", "3", "--seed", "5"], dict(mode="direct", spp=1, samples=3, seed=5)),
        (
            ["--mode", "ao", "--samples", "2", "--spp", "3", "--sampler", "sobol", "--ao-distance", "0.5"],
            dict(mode="ao", spp=3, samples=2, sampler="sobol", ao_distance=0.5),
        ),
        (["--mode", "shadows"], dict(mode="shadows", spp=1)),
        (["--spp", "2", "--max-depth", "3", "--seed", "9"], dict(spp=2, max_depth=3, seed=9)),
    ],
)
def test_values_are_the_cli_pfm_bit_for_bit(cli, tmp_path, flags, kwargs):
    out = tmp_path / "cli.pfm"
    cli("render", "--size", "48x36", *flags, "-o", out)
    image = lumiere.render(lumiere.builtin(), size=(48, 36), **kwargs)
    assert np.array_equal(bits(image), bits(read_pfm(out)))


def test_a_look_at_camera_and_a_scene_file_match_the_cli(cli, tmp_path):
    obj = tmp_path / "tri.obj"
    obj.write_text("mtllib tri.mtl\nv -1 0 -1\nv 1 0 -1\nv 0 0 1\nv -1 2 -1\nv 1 2 -1\nv 0 2 1\n"
                   "usemtl floor\nf 1 3 2\nusemtl lamp\nf 4 5 6\n")
    (tmp_path / "tri.mtl").write_text("newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\nKe 4 4 4\n")
    out = tmp_path / "cli.pfm"
    cli("render", obj, "--size", "32x24", "--spp", "2", "--eye", "0,1,4", "--target", "0,1,0", "--fov", "50",
        "--emission", "lamp=6,6,6", "-o", out)
    scene = lumiere.load(obj, emission={"lamp": (6, 6, 6)})
    camera = lumiere.Camera.look_at((0, 1, 4), (0, 1, 0), fov=50, size=(32, 24))
    assert np.array_equal(bits(lumiere.render(scene, camera, spp=2)), bits(read_pfm(out)))
    # Without a camera: the CLI's framing view.
    cli("render", obj, "--size", "32x24", "--spp", "1", "--mode", "materials", "-o", out)
    framed = lumiere.render(lumiere.load(obj), mode="materials", spp=1, size=(32, 24))
    assert np.array_equal(bits(framed), bits(read_pfm(out)))


def test_same_seed_same_bits_for_any_thread_count():
    scene = lumiere.builtin()
    one = lumiere.render(scene, spp=3, size=(40, 30), threads=1)
    two = lumiere.render(scene, spp=3, size=(40, 30), threads=2)
    other = lumiere.render(scene, spp=3, size=(40, 30), seed=1)
    assert np.array_equal(bits(one), bits(two))
    assert not np.array_equal(bits(one), bits(other))


def test_threads_0_follows_rayon_num_threads_as_it_is_now(monkeypatch):
    # The pool kept for threads=0 was reused by its argument, not by the count it stood for: once
    # started, RAYON_NUM_THREADS no longer changed it, until another count came between.
    def threads():
        return lumiere.render_full(lumiere.builtin(), mode="hits", size=(8, 6)).stats["threads"]

    monkeypatch.setenv("RAYON_NUM_THREADS", "2")
    assert threads() == 2
    monkeypatch.setenv("RAYON_NUM_THREADS", "1")
    assert threads() == 1


def test_aovs_come_back_as_a_dict_of_arrays():
    out = lumiere.render(lumiere.builtin(), spp=2, size=(32, 24), aovs=("albedo", "normal", "depth"))
    assert set(out) == {"color", "albedo", "normal", "depth"}
    assert out["albedo"].shape == out["normal"].shape == (24, 32, 3) and out["depth"].shape == (24, 32)
    assert all(a.dtype == np.float32 for a in out.values())
    assert 0 <= out["albedo"].min() and out["albedo"].max() <= 1
    lengths = np.linalg.norm(out["normal"], axis=2)
    assert np.all(lengths < 1.01) and np.mean(lengths > 0.99) > 0.5, "unit normals where the rays hit"
    assert np.array_equal(bits(out["color"]), bits(lumiere.render(lumiere.builtin(), spp=2, size=(32, 24))))


def test_scene_from_arrays_and_info():
    vertices = np.array([[-1, 0, -1], [1, 0, -1], [0, 0, 1], [-1, 2, -1], [1, 2, -1], [0, 2, 1]], dtype=np.float64)
    triangles = np.array([[0, 2, 1], [3, 4, 5]])
    scene = lumiere.Scene.from_arrays(
        vertices, triangles, materials=["floor", {"name": "lamp", "kd": (0, 0, 0), "ke": (5, 5, 5)}], material_ids=[0, 1]
    )
    info = scene.info()
    assert info["triangles"] == 2 and info["vertices"] == 6
    assert set(info["materials"]) == {"floor", "lamp"} and info["materials"]["lamp"]["light"]
    assert info["lights"]["triangles"] == 1
    assert info["bounds"] == ([-1.0, 0.0, -1.0], [1.0, 2.0, 1.0])
    camera = lumiere.Camera.look_at((0, 1, 4), (0, 1, 0), size=(16, 12))
    image = lumiere.render(scene, camera, spp=2)
    assert image.shape == (12, 16, 3) and image.max() > 0
    # Pickled scenes and cameras (what Ray ships) rebuild to the same render.
    again = lumiere.render(pickle.loads(pickle.dumps(scene)), pickle.loads(pickle.dumps(camera)), spp=2)
    assert np.array_equal(bits(image), bits(again))
    with pytest.raises(lumiere.LumiereError, match="triangles index vertices 0..5"):
        lumiere.Scene.from_arrays(vertices, [[0, 1, 6]])
    with pytest.raises(lumiere.LumiereError, match=r"vertices must have shape \(N, 3\)"):
        lumiere.Scene.from_arrays(np.zeros((4, 2)), [[0, 1, 2]])


def test_a_binary_ply_file_renders_as_the_same_arrays(tmp_path):
    # A binary PLY as numpy writes one, with normals: the same render as the arrays it holds, and
    # its one material is the one emission names.
    vertices = np.array([[-1, 0, -1], [1, 0, -1], [0, 0, 1], [-1, 2, -1], [1, 2, -1], [0, 2, 1]], dtype="<f4")
    triangles = np.array([[0, 2, 1], [3, 4, 5]], dtype="<i4")
    faces = np.zeros(2, dtype=[("n", "u1"), ("corners", "<i4", 3)])
    faces["n"], faces["corners"] = 3, triangles
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
              "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n")
    ply = tmp_path / "two.ply"
    ply.write_bytes(header.encode() + vertices.tobytes() + faces.tobytes())
    scene = lumiere.load(ply, emission={"default": (1, 1, 1)})
    assert scene.warnings == [] and scene.info()["triangles"] == 2
    twin = lumiere.Scene.from_arrays(vertices, triangles, materials=[{"name": "default", "ke": (1, 1, 1)}])
    camera = lumiere.Camera.look_at((0, 1, 4), (0, 1, 0), size=(16, 12))
    image = lumiere.render(scene, camera, spp=2)
    assert image.max() > 0
    assert np.array_equal(bits(image), bits(lumiere.render(twin, camera, spp=2)))
    assert np.array_equal(bits(image), bits(lumiere.render(pickle.loads(pickle.dumps(scene)), camera, spp=2)))
    ply.write_bytes(header.encode() + vertices.tobytes() + faces.tobytes()[:-3])
    with pytest.raises(lumiere.LumiereError, match=r"two\.ply: byte \d+: face 1: the file ends"):
        lumiere.load(ply)


def two_panels_gltf(buffer_file, uri, nodes, roots):
    """A glTF document of two triangles (material ``panel``, mesh 0) drawn by ``nodes`` from the
    scene's ``roots``, its buffer written to ``buffer_file`` and named by ``uri``; and the
    buffer's bytes."""
    vertices = np.array([[-1, 0, -1], [1, 0, -1], [0, 0, 1], [-1, 2, -1], [1, 2, -1], [0, 2, 1]], dtype="<f4")
    indices = np.array([0, 2, 1, 3, 4, 5], dtype="<u2")
    data = vertices.tobytes() + indices.tobytes()
    buffer_file.write_bytes(data)
    document = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": roots}], "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "materials": [{"name": "panel", "pbrMetallicRoughness": {"metallicFactor": 0}}],
        "buffers": [{"uri": uri, "byteLength": len(data)}],
        "bufferViews": [{"buffer": 0, "byteLength": 72}, {"buffer": 0, "byteOffset": 72, "byteLength": 12}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 6, "type": "VEC3"},
                      {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}],
    }
    return document, data


def test_a_gltf_file_loads_pickles_and_renders(tmp_path):
    # A .gltf with its buffer beside it, as numpy writes one: its materials by name for emission,
    # the same bits after a pickle (which reloads the file), and a cut buffer named in the error.
    import json

    nodes = [{"mesh": 0, "translation": [0, 0.5, 0]}]
    document, data = two_panels_gltf(tmp_path / "two data.bin", "two%20data.bin", nodes, [0])
    path = tmp_path / "two.gltf"
    path.write_text(json.dumps(document))
    scene = lumiere.load(path, emission={"panel": (1, 1, 1)})
    assert scene.warnings == [] and scene.info()["triangles"] == 2
    camera = lumiere.Camera.look_at((0, 1, 4), (0, 1, 0), size=(16, 12))
    image = lumiere.render(scene, camera, spp=2)
    assert image.max() > 0
    assert np.array_equal(bits(image), bits(lumiere.render(pickle.loads(pickle.dumps(scene)), camera, spp=2)))
    (tmp_path / "two data.bin").write_bytes(data[:-3])
    with pytest.raises(lumiere.LumiereError, match=r"two\.gltf: buffer 0: declares 84 bytes, but its data has 81"):
        lumiere.load(path)


def test_a_gltf_camera_is_the_default_view(tmp_path):
    # A camera node (half a turn about +Y, so looking down +Z) is the scene's view: render with
    # camera=None draws what Camera.look_at of that view draws, bit for bit, and a Camera made of
    # it pickles as a look-at. A file without a camera has no view, and renders framed.
    import json

    nodes = [{"mesh": 0}, {"camera": 0, "translation": [0.5, 1.5, -4], "rotation": [0, 1, 0, 0]}]
    document, _ = two_panels_gltf(tmp_path / "data.bin", "data.bin", nodes, [0, 1])
    document["cameras"] = [{"name": "Main", "type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}]
    with_camera = tmp_path / "camera.gltf"
    with_camera.write_text(json.dumps(document))
    del document["cameras"]
    document["nodes"][1] = {}
    plain = tmp_path / "plain.gltf"
    plain.write_text(json.dumps(document))

    scene = lumiere.load(with_camera, emission={"panel": (1, 1, 1)})
    assert scene.warnings == []
    view = scene.view
    assert view["eye"] == (0.5, 1.5, -4.0) and view["name"] == "Main"
    assert np.allclose(np.subtract(view["target"], view["eye"]) / 4, (0, 0, 1), atol=1e-6)
    assert np.allclose(view["up"], (0, 1, 0), atol=1e-6)
    assert view["fov"] == pytest.approx(math.degrees(0.7), abs=1e-4)
    assert scene.info()["view"] == view

    size = (16, 12)
    explicit = lumiere.Camera.look_at(view["eye"], view["target"], view["up"], view["fov"], size)
    image = lumiere.render(scene, spp=2, size=size)
    assert image.max() > 0
    assert np.array_equal(bits(image), bits(lumiere.render(scene, explicit, spp=2)))
    framed = lumiere.render(scene, lumiere.Camera.framing(scene, size), spp=2)
    assert not np.array_equal(bits(image), bits(framed))

    camera = lumiere.Camera.scene_view(scene, size)
    assert repr(camera) == repr(explicit)
    again = pickle.loads(pickle.dumps(camera))
    assert np.array_equal(bits(image), bits(lumiere.render(scene, again, spp=2)))

    without = lumiere.load(plain, emission={"panel": (1, 1, 1)})
    assert without.view is None and without.info()["view"] is None
    assert np.array_equal(bits(lumiere.render(without, spp=2, size=size)), bits(framed))
    with pytest.raises(lumiere.LumiereError, match=r"plain\.gltf: the scene has no view of its own"):
        lumiere.Camera.scene_view(without, size)


def grey_png(path, values):
    """A one-row 8-bit grey PNG of `values`, written without an imaging library."""
    import struct
    import zlib

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", len(values), 1, 8, 0, 0, 0, 0)
    pixels = zlib.compress(b"\x00" + bytes(values))
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", pixels) + chunk(b"IEND", b""))


def test_texture_placement_and_parameter_maps_show_in_info(tmp_path):
    obj = tmp_path / "tiles.obj"
    obj.write_text("mtllib tiles.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                   "usemtl tiles\nf 1/1 2/2 3/3\nusemtl plain\nf 1/1 2/2 3/3\n")
    (tmp_path / "tiles.mtl").write_text("newmtl tiles\nmap_Kd -s 4 2 1 -o 0.5 0 my tiles.png\nmap_d -o 0.25 mask.png\n"
                                        "map_Pr -imfchan g orm.png\nmap_Bump -bm 0.5 bumps.png\n"
                                        "newmtl plain\nmap_Kd plain.png\nnorm normals.png\n")
    materials = lumiere.load(obj).info()["materials"]
    tiles, plain = materials["tiles"], materials["plain"]
    assert tiles["texture"] == str(tmp_path / "my tiles.png")
    assert tiles["texture_placement"] == {"scale": [4.0, 2.0], "offset": [0.5, 0.0]}
    assert tiles["cutout_placement"] == {"scale": [1.0, 1.0], "offset": [0.25, 0.0]}
    assert plain["texture_placement"] is None and plain["cutout_placement"] is None
    assert tiles["roughness_texture"] == str(tmp_path / "orm.png") and tiles["metallic_texture"] is None
    assert plain["roughness_texture"] is None
    assert tiles["bump_texture"] == str(tmp_path / "bumps.png") and tiles["normal_texture"] is None
    assert plain["normal_texture"] == str(tmp_path / "normals.png") and plain["bump_texture"] is None


def test_texture_warnings_reach_python_as_the_cli_prints_them(cli, tmp_path):
    obj = tmp_path / "j2.obj"
    obj.write_text("mtllib j2.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nvt 0 0\nusemtl m\nf 1/1 2/1 3/1\n")
    (tmp_path / "j2.mtl").write_text("newmtl m\nKd 1 1 1\nmap_Kd missing.png\n")
    with pytest.warns(UserWarning, match="missing.png") as caught:
        scene = lumiere.load(obj)
    missing = tmp_path / "missing.png"
    expected = f'texture "{missing}": No such file or directory (os error 2); the material\'s Kd is used instead'
    assert scene.warnings == [expected] and scene.info()["warnings"] == [expected]
    assert [str(w.message) for w in caught] == [expected]
    assert [w.filename for w in caught] == [__file__]
    printed = cli("render", obj, "--mode", "materials", "--size", "8x6", "-o", tmp_path / "x.pfm").stderr
    assert f"lumiere: warning: {expected}" in printed.splitlines()


def test_cutouts_show_in_info_and_render_the_cli_bytes(cli, tmp_path):
    grey_png(tmp_path / "mask.png", [0, 255])
    obj = tmp_path / "leaf.obj"
    obj.write_text("mtllib leaf.mtl\nv -1 0 -1\nv 1 0 -1\nv 0 0 1\nv -1 1 -1\nv 1 1 -1\nv 1 1 1\nv -1 1 1\n"
                   "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl floor\nf 1 3 2\nusemtl leaf\nf 4/1 7/4 6/3\nf 4/1 6/3 5/2\n")
    (tmp_path / "leaf.mtl").write_text("newmtl floor\nKd 0.5 0.5 0.5\nnewmtl leaf\nKd 0.2 0.6 0.2\nmap_d mask.png\n")
    scene = lumiere.load(obj)
    assert scene.info()["materials"]["leaf"]["cutout"] == str(tmp_path / "mask.png")
    assert scene.info()["materials"]["floor"]["cutout"] is None
    out = tmp_path / "cli.pfm"
    cli("render", obj, "--size", "32x24", "--mode", "materials", "--eye", "0,3,2", "--target", "0,0,0", "-o", out)
    camera = lumiere.Camera.look_at((0, 3, 2), (0, 0, 0), size=(32, 24))
    image = lumiere.render(scene, camera, mode="materials", spp=1)
    assert np.array_equal(bits(image), bits(read_pfm(out)))
    # Half the leaf is cut out: the floor's grey shows where the leaf's green would.
    pixels = image.reshape(-1, 3)
    for colour in [(0.2, 0.6, 0.2), (0.5, 0.5, 0.5)]:
        assert np.isclose(pixels, colour).all(axis=1).any(), colour


def test_builtin_info_lists_materials_by_name():
    info = lumiere.builtin().info()
    assert info["triangles"] == 32 and info["lights"]["triangles"] == 2
    assert "light.001" in info["materials"] and info["materials"]["light.001"]["light"]


def test_errors_carry_the_cli_message(cli, tmp_path):
    missing = tmp_path / "missing.obj"
    with pytest.raises(lumiere.LumiereOSError) as error:
        lumiere.load(missing)
    assert isinstance(error.value, OSError) and isinstance(error.value, lumiere.LumiereError)
    assert error.value.errno == 2 and error.value.filename == str(missing)
    cli_error = cli("render", missing, "-o", tmp_path / "x.pfm", check=False).stderr.strip().splitlines()[-1]
    assert cli_error == f"lumiere: error: {error.value}"

    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2 9\n")
    with pytest.raises(lumiere.LumiereError) as error:
        lumiere.load(bad)
    assert not isinstance(error.value, OSError)
    cli_error = cli("render", bad, "-o", tmp_path / "x.pfm", check=False).stderr.strip().splitlines()[-1]
    assert cli_error == f"lumiere: error: {error.value}"

    with pytest.raises(lumiere.LumiereError, match="same point"):
        lumiere.Camera.look_at((0, 0, 0), (0, 0, 0))
    with pytest.raises(lumiere.LumiereError, match="unknown mode"):
        lumiere.render(lumiere.builtin(), mode="nope")
    with pytest.raises(lumiere.LumiereError, match="spp must be between 1 and 4294967294, got 0"):
        lumiere.render(lumiere.builtin(), spp=0)
    with pytest.raises(lumiere.LumiereError, match="unknown AOV"):
        lumiere.render(lumiere.builtin(), spp=1, size=(8, 6), aovs=("speed",))
    with pytest.raises(TypeError, match="technique options are"):
        lumiere.render(lumiere.builtin(), spp=1, sample=3)
    # Ignored options are said at the caller's line, from render() as from render_full().
    for function in (lumiere.render, lumiere.render_full):
        with pytest.warns(UserWarning, match="samples has no effect") as caught:
            function(lumiere.builtin(), spp=1, size=(8, 6), samples=4)
        assert [w.filename for w in caught] == [__file__]


def test_numbers_are_checked_as_the_cli_checks_them(tmp_path):
    scene = lumiere.builtin()
    small = {"spp": 1, "size": (8, 6)}
    # Integers of any kind numpy or Python has, never a bool, a float or one out of range.
    image = lumiere.render(scene, seed=np.int64(2), threads=np.int32(1), **small)
    assert np.array_equal(bits(image), bits(lumiere.render(scene, seed=2, threads=1, **small)))
    refused = [
        ({"threads": 2000}, "threads .* must be between 0 and 1024"),
        ({"threads": True}, "must be an integer"),
        ({"seed": -1}, "seed must be between 0"),
        ({"spp": 2**32}, "spp must be between 1 and 4294967294"),
        ({"spp": True}, "spp must be an integer"),
        ({"size": (8.9, 8.2)}, "size must be an integer"),
        ({"size": (2**32, 1)}, "size must be between 0 and 4294967295"),
        ({"max_depth": -1}, "max_depth must be between 0"),
        ({"samples": 0, "mode": "ao"}, "samples must be between 1"),
    ]
    for kwargs, message in refused:
        with pytest.raises(lumiere.LumiereError, match=message):
            lumiere.render(scene, **{**small, **kwargs})
    # Emission, colours and normals: finite, and emission not negative, as the loaders require.
    for ke in ((float("nan"), 1, 1), (-5, 1, 1), (float("inf"), 1, 1)):
        with pytest.raises(lumiere.LumiereError, match="must be finite and not negative"):
            lumiere.builtin(emission={"light.001": ke})
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float32)
    with pytest.raises(lumiere.LumiereError, match="must be finite"):
        lumiere.Scene.from_arrays(vertices, [[0, 1, 2]], materials=[{"name": "m", "kd": (float("nan"), 0, 0)}])
    normals = np.array([[0, 0, 1], [0, 0, 1], [0, float("nan"), 1]], dtype=np.float32)
    with pytest.raises(lumiere.LumiereError, match="normal 2 is not finite"):
        lumiere.Scene.from_arrays(vertices, [[0, 1, 2]], normals=normals)
    for exposure in (float("nan"), 64.5, -100):
        with pytest.raises(lumiere.LumiereError, match="exposure must be between -64 and 64 stops"):
            lumiere.write_image(tmp_path / "x.png", image, exposure=exposure)
    assert not (tmp_path / "x.png").exists()
    with pytest.raises(lumiere.LumiereError, match="is a directory, not a regular file"):
        lumiere.load(tmp_path)


def test_values_the_cli_would_refuse_are_refused(tmp_path):
    # Strings are sequences, but "111" is not a colour, nor "45" a field of view.
    with pytest.raises(lumiere.LumiereError, match="must be three numbers"):
        lumiere.builtin(emission={"light.001": "111"})
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float32)
    with pytest.raises(lumiere.LumiereError, match="materials must be a list"):
        lumiere.Scene.from_arrays(vertices, [[0, 1, 2]], materials="abc")
    with pytest.raises(lumiere.LumiereError, match="eye must fit in float32"):
        lumiere.Camera.look_at((1e39, 1, 4), (0, 1, 0))
    with pytest.raises(lumiere.LumiereError, match="fov must be a number"):
        lumiere.Camera.look_at((0, 1, 4), (0, 1, 0), fov="45")
    with pytest.raises(lumiere.LumiereError, match="the field of view must be in"):
        lumiere.Camera.framing(lumiere.builtin(), fov=0)
    with pytest.raises(TypeError, match="scene must be a lumiere.Scene"):
        lumiere.Camera.framing("x")
    # As --aov, --noise and --time: an AOV once, a finite noise target, a number of seconds.
    with pytest.raises(lumiere.LumiereError, match="aov 'albedo' is given twice"):
        lumiere.render(lumiere.builtin(), spp=1, size=(8, 6), aovs=("albedo", "albedo"))
    with pytest.raises(lumiere.LumiereError, match="noise must be a positive finite number"):
        lumiere.render(lumiere.builtin(), spp=None, size=(8, 6), noise=float("inf"))
    with pytest.raises(lumiere.LumiereError, match="time must be a number"):
        lumiere.render(lumiere.builtin(), spp=None, size=(8, 6), time=True)
    # A tiny time budget is a budget, as --time 1e-12s is, not a refused argument: one pass, or
    # none if it runs out first (a race at this size), which leaves no image.
    try:
        assert lumiere.render(lumiere.builtin(), spp=None, size=(8, 6), time=1e-12).shape == (6, 8, 3)
    except lumiere.LumiereError as error:
        assert "before the first pass completed" in str(error)
    # A budget spent before the first pass completed is an error, as the CLI's: it returned a
    # black image, as if rendered.
    with pytest.raises(lumiere.LumiereError, match="time budget reached before the first pass completed"):
        lumiere.render(lumiere.builtin(), mode="direct", samples=2_000_000, spp=None, size=(64, 48), time=0.3)
    # A colour outside [0, 1] is clamped and named, as an MTL's is.
    scene = lumiere.Scene.from_arrays(vertices, [[0, 1, 2]], materials=[{"name": "m", "kd": (-1, 0.5, 2)}])
    assert any("clamped to [0, 1]" in w for w in scene.warnings), scene.warnings
    # Paths as bytes, as os.fspath gives them.
    lumiere.write_image(os.fsencode(tmp_path / "x.pfm"), np.zeros((2, 2, 3), np.float32))
    assert (tmp_path / "x.pfm").exists()


def test_library_errors_name_the_parameters_not_the_cli_flags():
    for call, expected in [
        (lambda: lumiere.Camera.look_at((0, 1, 4), (0, 1, 4)), "camera: the eye and the target are the same point"),
        (lambda: lumiere.Camera.look_at((0, 1, 4), (0, 1, 0), up=(0, 0, 1)), "camera: the up vector is zero or parallel"),
        (lambda: lumiere.Camera.look_at((0, 1, 4), (0, 1, 0), fov=200), "camera: the field of view must be in (0, 180)"),
        (
            lambda: lumiere.render(lumiere.builtin(), mode="ao", ao_distance=-1, size=(8, 6)),
            "the ambient occlusion distance must be positive",
        ),
    ]:
        with pytest.raises(lumiere.LumiereError) as raised:
            call()
        message = str(raised.value)
        assert expected in message and "--" not in message, message


def test_progress_is_reported_and_an_exception_stops_the_render():
    calls = []
    lumiere.render(lumiere.builtin(), spp=4, size=(64, 48), progress=lambda done, total: calls.append((done, total)))
    assert calls[-1] == (64 * 48 * 4, 64 * 48 * 4)
    assert all(a[0] <= b[0] for a, b in zip(calls, calls[1:]))

    class Stop(Exception):
        pass

    def stop(done, total):
        if done > 0:
            raise Stop

    start = time.perf_counter()
    with pytest.raises(Stop):
        lumiere.render(lumiere.builtin(), spp=100_000, size=(64, 48), progress=stop)
    assert time.perf_counter() - start < 10


def test_a_noise_target_out_of_reach_is_a_warning_and_a_budget_silences_it():
    # Hours away at this rate: a RuntimeWarning after about two seconds, issued in the caller's
    # thread; made an error by a filter, it stops the render as a callback's exception does.
    start = time.perf_counter()

    def give_up(done, total):
        # Without the warning the render would never end: fail instead of hanging.
        if time.perf_counter() - start > 30:
            raise TimeoutError("no warning within 30 s")

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(RuntimeWarning, match=r"noise=1e-9: the relative error is .* years more; the render goes on"):
            lumiere.render(lumiere.builtin(), mode="ao", samples=4, spp=None, size=(32, 24), noise=1e-9, progress=give_up)
    # Issued at the caller's line, from render() as from render_full() (a callback stops them).
    for function in (lumiere.render, lumiere.render_full):
        start = time.perf_counter()

        def stop_soon(done, total):
            if time.perf_counter() - start > 3:
                raise KeyboardInterrupt

        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with pytest.raises(KeyboardInterrupt):
                function(lumiere.builtin(), mode="ao", samples=4, spp=None, size=(32, 24), noise=1e-9, progress=stop_soon)
        assert [(w.filename, w.category) for w in caught] == [(__file__, RuntimeWarning)], [str(w.message) for w in caught]
    # A time budget that ends the render sooner: no warning.
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lumiere.render(lumiere.builtin(), mode="ao", samples=4, spp=None, size=(32, 24), noise=1e-9, time=3.0)
    assert not [w for w in caught if "noise=" in str(w.message)], [str(w.message) for w in caught]


def test_the_gil_is_released_while_rendering():
    ticks = []
    running = threading.Event()

    def count():
        running.set()
        while not done.is_set():
            ticks.append(1)
            time.sleep(0.001)

    done = threading.Event()
    thread = threading.Thread(target=count)
    thread.start()
    running.wait()
    before = len(ticks)
    lumiere.render(lumiere.builtin(), spp=16, size=(128, 96), threads=1)
    during = len(ticks) - before
    done.set()
    thread.join()
    assert during > 20, "a Python thread kept running during the render"


def test_ctrl_c_stops_the_render_and_raises_keyboard_interrupt(tmp_path):
    script = textwrap.dedent(
        """
        import signal, sys, lumiere
        # Python raises KeyboardInterrupt only where SIGINT is not ignored at its start: a
        # harness run in the background (`cmd &`, nohup) passes it on ignored.
        signal.signal(signal.SIGINT, signal.default_int_handler)
        def progress(done, total):
            if not progress.said:
                print("started", flush=True)
                progress.said = True
        progress.said = False
        try:
            lumiere.render(lumiere.builtin(), spp=1_000_000, size=(128, 96), progress=progress)
        except KeyboardInterrupt:
            print("KeyboardInterrupt", flush=True)
            sys.exit(7)
        """
    )
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout.readline().strip() == "started"
        sent = time.perf_counter()
        child.send_signal(signal.SIGINT)
        assert child.wait(timeout=20) == 7
        assert child.stdout.read().strip() == "KeyboardInterrupt"
        assert time.perf_counter() - sent < 5, "the render stopped promptly"
    finally:
        child.kill()


def test_ctrl_c_while_an_image_encodes_raises_at_once_and_writes_nothing(tmp_path):
    # A 36-megapixel PNG of noise takes seconds to encode on one thread: Ctrl-C must not wait for
    # it, and the file must keep its old bytes, even once the encoding left running has ended (the
    # next write waits for it).
    target, other = tmp_path / "big.png", tmp_path / "small.png"
    target.write_bytes(b"old")
    script = textwrap.dedent(
        f"""
        import signal, numpy as np, lumiere
        signal.signal(signal.SIGINT, signal.default_int_handler)
        image = np.random.default_rng(0).random((6000, 6000, 3), dtype=np.float32)
        try:
            lumiere.write_image({str(target)!r}, image)
            print("written", flush=True)
        except KeyboardInterrupt:
            print("KeyboardInterrupt", flush=True)
        lumiere.write_image({str(other)!r}, image[:2, :2])
        print(open({str(target)!r}, "rb").read() == b"old", flush=True)
        """
    )
    with _interrupted_at_work(script, "the encoding") as child:
        assert child.stdout.readline().strip() == "True", "the interrupted write replaced the file"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.png", "small.png"]


def test_ctrl_c_while_a_scene_builds_raises_keyboard_interrupt_at_once():
    # A BVH build cannot stop part-way: it ends in the background, unused, while Python goes on;
    # the next load waits for it, so that interrupted builds never pile up. Three million
    # triangles on one thread take seconds to build: the interrupt must not wait for them, and
    # the load after it must.
    script = textwrap.dedent(
        """
        import signal, sys, time, numpy as np, lumiere
        signal.signal(signal.SIGINT, signal.default_int_handler)
        n = 3_000_000
        rng = np.random.default_rng(1)
        centres = rng.random((n, 1, 3), dtype=np.float32) * 100
        vertices = (centres + rng.random((n, 3, 3), dtype=np.float32)).reshape(-1, 3)
        triangles = np.arange(3 * n, dtype=np.uint32).reshape(n, 3)
        try:
            lumiere.Scene.from_arrays(vertices, triangles)
            print("built", flush=True)
        except KeyboardInterrupt:
            print("KeyboardInterrupt", flush=True)
        start = time.perf_counter()
        lumiere.builtin()
        print(time.perf_counter() - start, flush=True)
        """
    )
    with _interrupted_at_work(script, "the build") as child:
        next_load = float(child.stdout.readline())
        assert next_load > 0.3, f"the next load started beside the build left running ({next_load:.3f} s)"


@contextlib.contextmanager
def _interrupted_at_work(script, work):
    """Runs `script` in a child process on one thread and sends it SIGINT 0.3 s after its
    `lumiere-work` thread starts (not while numpy makes its arrays): the child must print
    `KeyboardInterrupt` within 1.5 s. Yields the child for the checks after that, then expects it
    to exit cleanly."""
    env = dict(os.environ, RAYON_NUM_THREADS="1")
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True, env=env)
    try:
        threads = f"/proc/{child.pid}/task"
        deadline = time.perf_counter() + 60
        while not any(_thread_name(threads, task) == "lumiere-work" for task in _listed(threads)):
            assert time.perf_counter() < deadline and child.poll() is None, f"{work} never started"
            time.sleep(0.01)
        time.sleep(0.3)
        sent = time.perf_counter()
        child.send_signal(signal.SIGINT)
        assert child.stdout.readline().strip() == "KeyboardInterrupt"
        waited = time.perf_counter() - sent
        assert waited < 1.5, f"the interrupt waited {waited:.2f} s for {work}"
        yield child
        assert child.wait(timeout=60) == 0
    finally:
        child.kill()


def test_a_process_forked_after_rendering_loads_and_renders_too():
    # multiprocessing's "fork" (the default on Linux before Python 3.14) copies the thread pools
    # a load or a render started, but not their threads: work handed to them waited forever.
    script = textwrap.dedent(
        """
        import multiprocessing, lumiere
        def render(_):
            return lumiere.render(lumiere.builtin(), spp=1, size=(32, 24), threads=2).tobytes()
        if __name__ == "__main__":
            parent = render(0)
            with multiprocessing.get_context("fork").Pool(1) as pool:
                child = pool.apply_async(render, (0,)).get(timeout=20)
            print("same" if child == parent else "different", flush=True)
        """
    )
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert result.stdout.strip() == "same", result.stderr[-2000:]


def test_a_process_forked_from_a_progress_callback_gives_up_the_render():
    # The child has no render thread (a fork copies only the calling one): it must say so
    # rather than wait for that thread forever; the parent renders on.
    script = textwrap.dedent(
        """
        import os, lumiere
        forked = []
        def progress(done, total):
            if not forked:
                forked.append(os.fork())
        try:
            lumiere.render(lumiere.builtin(), spp=50, size=(128, 96), progress=progress)
            print("rendered" if forked[0] else "child rendered", flush=True)
        except lumiere.LumiereError as error:
            print(f"child: {error}", flush=True)
        if forked[0] == 0:
            os._exit(0)
        os.waitpid(forked[0], 0)
        """
    )
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    lines = sorted(result.stdout.splitlines())
    assert len(lines) == 2 and lines[1] == "rendered", (result.stdout, result.stderr[-2000:])
    assert lines[0].startswith("child: this process was forked during a render"), lines


def _listed(folder):
    try:
        return os.listdir(folder)
    except FileNotFoundError:
        return []


def _thread_name(tasks, task):
    try:
        with open(os.path.join(tasks, task, "comm")) as comm:
            return comm.read().strip()
    except OSError:
        return None


def test_write_image_writes_the_cli_bytes(cli, tmp_path):
    for extension in ("pfm", "png", "exr"):
        cli("render", "--size", "32x24", "--spp", "2", "-o", tmp_path / f"cli.{extension}")
        image = lumiere.render(lumiere.builtin(), spp=2, size=(32, 24))
        lumiere.write_image(tmp_path / f"py.{extension}", image)
        assert (tmp_path / f"py.{extension}").read_bytes() == (tmp_path / f"cli.{extension}").read_bytes(), extension


def test_write_image_with_aovs_writes_the_cli_exr(cli, tmp_path):
    cli("render", "--size", "32x24", "--spp", "3", "--aov", "depth,albedo,normal", "-o", tmp_path / "cli.exr")
    out = lumiere.render(lumiere.builtin(), spp=3, size=(32, 24), aovs=("normal", "depth", "albedo"))
    # The dict render returns, "color" and all: its AOVs become the EXR's channels.
    lumiere.write_image(tmp_path / "py.exr", out["color"], aovs=out)
    assert (tmp_path / "py.exr").read_bytes() == (tmp_path / "cli.exr").read_bytes()
    # Without the AOVs, another file.
    lumiere.write_image(tmp_path / "plain.exr", out["color"])
    assert (tmp_path / "plain.exr").read_bytes() != (tmp_path / "cli.exr").read_bytes()
    for aovs, error in (
        ({"albedo": out["albedo"]}, r"png: extra layers \(AOVs\) need an .exr output"),
        ({"colour": out["albedo"]}, 'unknown AOV "colour"'),
        ({"depth": out["albedo"][:, :, 0:2]}, r"aovs\['depth'\] must have shape \(24, 32\) as the image, got \(24, 32, 2\)"),
        ({"normal": out["normal"][:-1]}, r"aovs\['normal'\] must have shape \(24, 32, 3\) as the image, got \(23, 32, 3\)"),
        ({"albedo": np.array([[["a"] * 3] * 32] * 24)}, r"aovs\['albedo'\] must hold numbers"),
        ({"noisy": out["depth"]}, r"aovs\['noisy'\] must have shape \(24, 32, 3\) as the image, got \(24, 32\)"),
    ):
        with pytest.raises(lumiere.LumiereError, match=error):
            lumiere.write_image(tmp_path / ("x.png" if "png" in error else "x.exr"), out["color"], aovs=aovs)
    with pytest.raises(TypeError, match="aovs must be a dict of arrays by AOV name, got list"):
        lumiere.write_image(tmp_path / "x.exr", out["color"], aovs=["albedo"])
    assert sorted(os.listdir(tmp_path)) == ["cli.exr", "plain.exr", "py.exr"]


def test_a_render_that_comes_out_black_says_why(tmp_path):
    # As the CLI says it, in the package's words: no emitter, emitters that cannot emit, and an
    # image no camera ray lit; each a RuntimeWarning at the caller's line (they were silent).
    unlit = tmp_path / "unlit.obj"
    unlit.write_text("v -1 0 -1\nv 1 0 -1\nv 0 0 1\nf 1 3 2\n")
    camera = lumiere.Camera.look_at((0, 1, 3), (0, 0, 0), size=(8, 8))
    with pytest.warns(RuntimeWarning, match="the scene has no emitters") as caught:
        lumiere.render(lumiere.load(str(unlit)), camera, spp=1)
    assert all(w.filename == __file__ for w in caught), [(w.filename, str(w.message)) for w in caught]
    flat = tmp_path / "flat.obj"
    flat.write_text("v -1 0 -1\nv 1 0 -1\nv 0 0 1\nv 0 0 0\nf 1 3 2\nusemtl lamp\nf 4 4 4\n")
    with pytest.warns(RuntimeWarning, match='no triangle of the emitting material "lamp" can emit'):
        lumiere.render(lumiere.load(str(flat), emission={"lamp": (1, 1, 1)}), camera, spp=1)
    away = lumiere.Camera.look_at((0, 1, 3.9), (0, 1, 10), size=(8, 6))
    with pytest.warns(RuntimeWarning, match="the image is black: no camera ray hit the scene"):
        lumiere.render(lumiere.builtin(), away, spp=1, mode="hits")
    with pytest.warns(RuntimeWarning, match="the image is black: no camera ray reached a lit surface; check the camera with the hits mode"):
        lumiere.render(lumiere.builtin(), away, spp=1, mode="path")
    # A lit render says nothing of the kind.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lumiere.render(lumiere.builtin(), spp=1, size=(8, 6), mode="hits")


def test_arguments_found_by_a_hostile_sweep(tmp_path):
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
    # Complex numbers and strings of digits are not vertices (the imaginary part was dropped).
    for wrong in (vertices.astype(complex), vertices.astype(str)):
        with pytest.raises(lumiere.LumiereError, match="vertices must be an array of numbers"):
            lumiere.Scene.from_arrays(wrong, [[0, 1, 2]])
    # Values beyond float32 become infinities without numpy's warning from inside the package.
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lumiere.write_image(str(tmp_path / "big.pfm"), np.full((2, 2, 3), 1e300))
        with pytest.raises(lumiere.LumiereError):
            lumiere.Scene.from_arrays(vertices.astype(np.float64) * 1e300, [[0, 1, 2]])
    assert not caught, [(w.filename, str(w.message)) for w in caught]
    # A budget too long for a duration is said to be one, not "not positive".
    with pytest.raises(lumiere.LumiereError, match="too long a duration"):
        lumiere.render(lumiere.builtin(), spp=None, size=(8, 6), time=1e300)
    # No AOVs as None; a progress that cannot be called, refused before rendering.
    assert lumiere.render(lumiere.builtin(), spp=1, size=(8, 6), aovs=None).shape == (6, 8, 3)
    with pytest.raises(TypeError, match="progress must be callable"):
        lumiere.render(lumiere.builtin(), spp=1, size=(8, 6), progress=3)
    # No materials for triangles that need one: named for what it is.
    with pytest.raises(lumiere.LumiereError, match="materials must name at least one material"):
        lumiere.Scene.from_arrays(vertices, [[0, 1, 2]], materials=[])
    # The second sweep's: an empty list of triangles is no triangles (numpy reads it as floats);
    # a dict of materials is not a list of their names; AOVs that are not a list are named so;
    # a path that is not one says what a path must be.
    assert lumiere.Scene.from_arrays(vertices, []).info()["triangles"] == 0
    with pytest.raises(lumiere.LumiereError, match="materials must be a list of names or dicts"):
        lumiere.Scene.from_arrays(vertices, [[0, 1, 2]], materials={"a": 1})
    with pytest.raises(lumiere.LumiereError, match="aovs must be a list of names"):
        lumiere.render(lumiere.builtin(), spp=1, size=(8, 6), aovs=3)
    for call in (lambda: lumiere.load(None), lambda: lumiere.load(3), lambda: lumiere.write_image(None, vertices[None])):
        with pytest.raises(TypeError, match="a path must be a str, bytes or os.PathLike, got"):
            call()


@pytest.mark.skipif(sys.platform != "linux", reason="an address-space limit, as the CLI's tests use")
def test_aovs_that_do_not_fit_beside_the_film_are_refused_before_rendering():
    # Under a 2 GiB address-space limit a 5000x4000 film fits alone, but not with three AOVs: one
    # line naming them, before rendering, not the allocator's abort of the interpreter after it.
    script = textwrap.dedent(
        """
        import resource, lumiere
        resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))
        try:
            lumiere.render(lumiere.builtin(), spp=1, size=(5000, 4000), mode="hits", aovs=("albedo", "normal", "depth"))
        except lumiere.LumiereError as error:
            print(error)
        """
    )
    child = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert child.returncode == 0, child.stderr
    assert "image size 5000x4000 with its AOVs needs" in child.stdout, (child.stdout, child.stderr)


@pytest.mark.skipif(sys.platform != "linux", reason="an address-space limit, as the CLI's tests use")
def test_arrays_too_large_for_memory_are_refused_before_they_are_copied():
    # 14M triangles need about 2.6 GB with their BVH: under a 2 GiB address-space limit, one line
    # naming the need, as an OBJ of that size gets, not the allocator's abort of the interpreter.
    script = textwrap.dedent(
        """
        import resource, numpy as np, lumiere
        resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))
        vertices = np.random.default_rng(0).random((3000, 3), dtype=np.float32)
        triangles = np.zeros((14_000_000, 3), dtype=np.uint32)
        triangles[:, 1], triangles[:, 2] = 1, 2
        try:
            lumiere.Scene.from_arrays(vertices, triangles)
        except lumiere.LumiereError as error:
            print(error)
        """
    )
    child = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert child.returncode == 0, child.stderr
    assert "arrays: needs about" in child.stdout and "14000000 triangles" in child.stdout, (child.stdout, child.stderr)


@pytest.mark.skipif(sys.platform != "linux", reason="an address-space limit, as the CLI's tests use")
def test_an_image_too_large_to_encode_is_refused_and_the_old_file_kept(tmp_path):
    # A 45-megapixel PFM under a 2 GiB address-space limit: the array, its bytes and the pixels
    # leave no room for the file's 540 MB. An exception, not the allocator's abort of the interpreter.
    target = tmp_path / "big.pfm"
    target.write_bytes(b"old")
    script = textwrap.dedent(
        f"""
        import resource, numpy as np, lumiere
        resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))
        try:
            lumiere.write_image({str(target)!r}, np.ones((11250, 4000, 3), np.float32))
        except lumiere.LumiereError as error:
            print(error)
        """
    )
    child = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert child.returncode == 0, child.stderr
    assert "out of memory" in child.stdout or "needs about" in child.stdout, (child.stdout, child.stderr)
    assert target.read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.pfm"]

"""Files the Python side reads and writes itself, under the CLI's rules: an orbiter file is read
as lumiere.load reads scenes (a regular file only), and lumiere.distributed (its function and its
command line) refuses, before any render, an output that would replace an input, a file the scene
reads, or another output. No Ray is needed: every refusal comes before the cluster is asked for."""

import errno
import os
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import lumiere
import lumiere.distributed as distributed

ORBITER = "c 0 1 0\np 0 0\nr 10 10\ns 2 3\nf 45 1024 640\n"
#: An address nothing listens on: reaching it would fail with another message.
NOWHERE = "127.0.0.1:9"


@pytest.fixture
def scene_files(tmp_path):
    """A scene whose OBJ reads an MTL and a texture, and an orbiter file beside them."""
    (tmp_path / "tq.obj").write_text("mtllib tq.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nvt 0 0\nusemtl m\nf 1/1 2/1 3/1\n")
    (tmp_path / "tq.mtl").write_text("newmtl m\nKd 1 1 1\nKe 1 1 1\nmap_Kd tex.png\n")
    (tmp_path / "tex.png").write_bytes(b"not a png")
    (tmp_path / "orbiter.txt").write_text(ORBITER)
    return tmp_path


def test_the_orbiter_is_read_as_a_regular_file_only(tmp_path):
    # A FIFO would block open().read() forever and /dev/zero never end: both are refused unread,
    # in a subprocess so that a hang fails the test instead of stalling it.
    os.mkfifo(tmp_path / "fifo")
    script = textwrap.dedent(f"""
        import lumiere
        for path in ({str(tmp_path / "fifo")!r}, "/dev/zero"):
            try:
                lumiere.Camera.orbiter(path, size=(8, 6))
            except lumiere.LumiereOSError as e:
                print(e)
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines() == [
        f"{tmp_path / 'fifo'}: is a FIFO, not a regular file",
        "/dev/zero: is a character device, not a regular file",
    ], result.stdout
    (tmp_path / "orbiter.txt").write_text(ORBITER)
    assert lumiere.Camera.orbiter(tmp_path / "orbiter.txt", size=(8, 6)).size == (8, 6)
    # A file name that is not UTF-8 (as bytes, and as Python decodes it) is a file name all the same.
    odd = os.fsencode(tmp_path) + b"/orbiter-\xff.txt"
    with open(odd, "w") as f:
        f.write(ORBITER)
    assert lumiere.Camera.orbiter(odd, size=(8, 6)).size == (8, 6)
    assert lumiere.Camera.orbiter(os.fsdecode(odd), size=(8, 6)).size == (8, 6)
    with pytest.raises(lumiere.LumiereOSError) as error:
        lumiere.Camera.orbiter(tmp_path / "missing.txt")
    assert error.value.errno == 2 and error.value.filename == str(tmp_path / "missing.txt")
    # An output in a folder that does not exist names the folder, and is still ENOENT.
    out = tmp_path / "no" / "such" / "x.png"
    with pytest.raises(lumiere.LumiereOSError, match=f"the folder {tmp_path / 'no' / 'such'} does not exist") as error:
        lumiere.write_image(str(out), np.zeros((2, 2, 3), np.float32))
    assert error.value.errno == errno.ENOENT and error.value.filename == str(out)


def test_the_render_function_never_writes_its_checkpoint_over_an_input(scene_files):
    with pytest.warns(UserWarning, match="tex.png"):
        scene = lumiere.load(scene_files / "tq.obj")
    camera = lumiere.Camera.orbiter(scene_files / "orbiter.txt", size=(8, 6))
    for checkpoint, message in (
        ("tq.mtl", "tq.mtl: the output would overwrite .*tq.mtl, which the scene reads"),
        ("tex.png", "tex.png: the output would overwrite .*tex.png, which the scene reads"),
        ("tq.obj", r"tq.obj \(checkpoint\) and .*tq.obj \(scene\) are the same file: an output would overwrite an input"),
        ("orbiter.txt", r"\(checkpoint\) and .*orbiter.txt \(camera\) are the same file"),
    ):
        before = (scene_files / checkpoint).read_bytes()
        with pytest.raises(lumiere.LumiereError, match=message):
            distributed.render(scene, camera, spp=1, address=NOWHERE, checkpoint=str(scene_files / checkpoint))
        assert (scene_files / checkpoint).read_bytes() == before


@pytest.mark.parametrize(
    "flags, message",
    [
        (["tq.obj", "--checkpoint", "tq.mtl"], "tq.mtl: the output would overwrite .*tq.mtl, which the scene reads"),
        (["tq.obj", "-o", "tex.png"], "tex.png: the output would overwrite .*tex.png, which the scene reads"),
        (["tq.obj", "-o", "tq.pfm", "--orbiter", "orbiter.txt", "--checkpoint", "orbiter.txt"],
         r"orbiter.txt \(--checkpoint\) and orbiter.txt \(--orbiter\) are the same file: an output would overwrite an input"),
        (["-o", "same.exr", "--checkpoint", "same.exr"],
         r"same.exr \(-o\) and same.exr \(--checkpoint\) are the same file: both outputs"),
    ],
)
def test_the_command_line_never_writes_over_an_input_or_another_output(scene_files, flags, message):
    before = {name: (scene_files / name).read_bytes() for name in os.listdir(scene_files)}
    command = [sys.executable, "-m", "lumiere.distributed", "render", "--address", NOWHERE, "--size", "8x6", *flags]
    result = subprocess.run(command, capture_output=True, text=True, timeout=120, cwd=scene_files)
    assert result.returncode == 2, result.stderr
    last = result.stderr.strip().splitlines()[-1]
    assert last.startswith("lumiere.distributed: error: ") and "no Ray cluster" not in last, result.stderr
    assert re.search(message, last), last
    assert {name: (scene_files / name).read_bytes() for name in os.listdir(scene_files)} == before


def test_writing_an_image_clears_away_temporaries_that_killed_writers_left(tmp_path):
    # As the CLI does before it writes: a temporary that no process holds and that has gone
    # unwritten for 10 s was left by a killed writer. Python's writes left them for ever.
    stale, live = tmp_path / ".lumiere-1-0.tmp", tmp_path / ".lumiere-1-1.tmp"
    stale.write_bytes(b"half an image")
    live.write_bytes(b"written just now")
    os.utime(stale, (0, 0))
    lumiere.write_image(tmp_path / "x.pfm", lumiere.render(lumiere.builtin(), mode="hits", size=(4, 3)))
    assert sorted(p.name for p in tmp_path.iterdir()) == [".lumiere-1-1.tmp", "x.pfm"]
